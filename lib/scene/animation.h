// Per-frame node transforms (DESIGN §3) from a qsgi-animation transform file. A node's entry
// replaces its local transform; nodes not listed keep their last transform.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <functional>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

class Animation {
public:
    // No animation: one frame, 0, in the rest pose.
    static Animation still(const Scene& scene);
    // Throws InputError naming the file, frame and node for anything unusable.
    static Animation fromTransformFile(const std::string& path, const Scene& scene);
    // The same for a transform file already parsed as JSON (`path` names it in messages; the
    // fuzzer uses this). Wrong JSON types may also throw nlohmann::json::exception.
    static Animation parseTransformFile(const std::string& path, const nlohmann::json& doc, const Scene& scene);

    int lastFrame() const { return lastFrame_; }
    double fps() const { return fps_; }
    // Local transform of every node at the frame (frames past the last keep the last pose).
    std::vector<Transform> localsAt(int frame) const;
    // Nodes whose local transform differs from the rest pose in some frame.
    const std::vector<int>& movedNodes() const { return moved_; }

private:
    struct Key {
        int frame;
        std::vector<std::pair<int, Transform>> nodes;
    };
    std::vector<Transform> rest_;
    std::vector<Key> keys_;  // increasing frame
    std::vector<int> moved_;
    int lastFrame_ = 0;
    double fps_ = 24;
};

// Poses the scene at every frame of the animation and sets scene.animationBounds to the union of
// their bounds, then returns the scene to its rest pose. Everything derived from the scene's size
// uses it, so no value depends on which frame is being rendered (DESIGN §6 step 0).
void sweepAnimationBounds(Scene& scene, const Animation& animation);
// The same for any source of poses: localsAt(frame) for frames 0…lastFrame.
void sweepAnimationBounds(Scene& scene, int lastFrame, const std::function<std::vector<Transform>(int)>& localsAt);

// Lights are static (DESIGN §2): throws InputError if a punctual light or an emissive mesh hangs
// under a node the animation moves.
void checkLightsAreStatic(const Scene& scene, const Animation& animation, const std::string& animationFile);

}  // namespace qsgi
