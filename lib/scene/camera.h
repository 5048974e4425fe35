// The view a frame is rendered from (docs/design.md §2): a perspective pinhole or an orthographic camera,
// as glTF defines them (looking down its node's −Z, +Y up).
#pragma once

#include "util/vecmath.h"

namespace qsgi {

enum class Projection { Perspective, Orthographic };

struct Camera {
    Projection projection = Projection::Perspective;
    Vec3f position{0.0f};               // scene frame (relative to Scene::worldOrigin)
    Vec3f forward{0, 0, -1}, up{0, 1, 0};  // unit; up need not be orthogonal to forward
    float yfov = 0.8f;                  // perspective: vertical field of view, radians
    float ymag = 1;                     // orthographic: half the view's height, scene units
    float aspect = 0;                   // width/height from the file; the image size decides
    float znear = 0.01f;
    int node = -1;                      // the glTF node that places it (-1: from the config or framing)
};

// A camera at `position` looking at `target`. Throws std::invalid_argument for a degenerate set.
Camera lookAtCamera(const Vec3f& position, const Vec3f& target, const Vec3f& up, float yfov);

// A camera that frames the bounds from their +z side, slightly above (used when a scene has none).
Camera framingCamera(const Bounds3f& bounds, float aspect);

// `lens` placed by its node's world transform: at the node's origin, looking down its −Z with +Y
// up, re-centred by the scene's worldOrigin.
Camera placeCamera(Camera lens, const Transform& world, const Vec3d& worldOrigin);

// The primary ray through image position (x, y) in pixels, y down. The image's aspect decides the
// horizontal extent (yfov or ymag fix the vertical one).
struct CameraRay {
    Vec3f origin, direction;
};
CameraRay cameraRay(const Camera& c, float x, float y, int width, int height);

// Whether the camera looks somewhere: unit forward and up that are not parallel. A camera placed
// by a singular transform (its node scaled to zero) has none.
bool hasDirection(const Camera& c);

}  // namespace qsgi
