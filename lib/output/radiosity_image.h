// A view of the per-vertex solution (docs/design.md §7): primary rays from the camera through Embree,
// pixel radiance B/π interpolated over the hit triangle by barycentrics, black background. No
// further bounces are traced: the image shows the view-independent solution as it is.
#pragma once

#include <vector>

#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"

namespace qsgi {

struct RgbImage {
    int width = 0, height = 0;
    std::vector<float> pixels;  // RGB, row-major, top row first
};

struct ImageSettings {
    int width = 640, height = 480;
    int samplesPerPixel = 1;  // 1: the pixel centre; more: jittered, the same jitter every run
    uint64_t seed = 1;
};

RgbImage renderRadiosityImage(const Scene& scene, const SceneBvh& bvh, const VertexRadiosity& solution,
                              const Camera& camera, const ImageSettings& settings);

}  // namespace qsgi
