// The view a frame is rendered from (DESIGN §2): a perspective pinhole camera.
#pragma once

#include "util/vecmath.h"

namespace qsgi {

struct PerspectiveCamera {
    Vec3f position{0.0f};               // scene frame (relative to Scene::worldOrigin)
    Vec3f forward{0, 0, -1}, up{0, 1, 0};  // unit; up need not be orthogonal to forward
    float yfov = 0.8f;                  // vertical field of view, radians
    float aspect = 0;                   // width/height from the file; the image size decides
    float znear = 0.01f;
};

// A camera at `position` looking at `target`. Throws std::invalid_argument for a degenerate set.
PerspectiveCamera lookAtCamera(const Vec3f& position, const Vec3f& target, const Vec3f& up, float yfov);

// A camera that frames the bounds from their +z side, slightly above (used when a scene has none).
PerspectiveCamera framingCamera(const Bounds3f& bounds, float aspect);

// Primary ray direction through image position (x, y) in pixels, y down.
Vec3f cameraRayDirection(const PerspectiveCamera& c, float x, float y, int width, int height);

}  // namespace qsgi
