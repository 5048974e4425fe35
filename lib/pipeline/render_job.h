// One render run: load and check every input, then per frame pose the scene, trace photons,
// estimate vertex radiosity and write the outputs (DESIGN §1). The CLI is a thin host over this.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "pipeline/render_settings.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "util/error.h"

namespace qsgi {

struct FrameReport {
    int frame;
    int index, count;  // position in the run
    double seconds;
    double missedFraction;  // of the photons emitted this frame, those that hit no geometry
};

class RenderJob {
public:
    // Loads the scene, animation and lights and checks them all; throws InputError before
    // anything is written.
    RenderJob(RenderSettings settings, Warnings& warnings);

    // Creates the output folder and renders every frame. onFrame runs after each frame.
    void run(const std::function<void(const FrameReport&)>& onFrame = {});

    const Scene& scene() const { return scene_; }
    int firstFrame() const { return first_; }
    int lastFrame() const { return last_; }

private:
    RenderSettings settings_;
    Scene scene_;
    PerspectiveCamera camera_;
    Animation animation_;
    int first_ = 0, last_ = 0;
};

// "frame_0012.ply" and the like.
std::string frameFileName(int frame, const char* extension);

}  // namespace qsgi
