#include "scene/camera.h"

#include <cmath>
#include <stdexcept>

namespace qsgi {

Camera lookAtCamera(const Vec3f& position, const Vec3f& target, const Vec3f& up, float yfov) {
    Camera c;
    c.position = position;
    c.forward = normalize(target - position);
    c.up = normalize(up);
    c.yfov = yfov;
    if (dot(c.forward, c.forward) == 0) throw std::invalid_argument("position and target coincide");
    if (length(cross(c.forward, c.up)) < 1e-6f) throw std::invalid_argument("up is parallel to the view direction");
    if (!(yfov > 0 && yfov < 3.1f)) throw std::invalid_argument("yfov must lie in (0, 3.1) radians");
    return c;
}

Camera framingCamera(const Bounds3f& bounds, float aspect) {
    const Vec3f centre = bounds.center();
    const float radius = std::max(0.5f * bounds.extent(), 1e-3f);
    const float yfov = 0.8f;
    // Distance at which the bounding sphere fits the narrower field of view.
    const float halfFov = std::min(yfov, 2 * std::atan(std::tan(yfov / 2) * std::max(aspect, 0.1f))) / 2;
    const float distance = radius / std::sin(halfFov);
    const Vec3f direction = normalize(Vec3f(0, 0.25f, 1));
    return lookAtCamera(centre + direction * distance, centre, Vec3f(0, 1, 0), yfov);
}

bool hasDirection(const Camera& c) {
    return length(c.forward) > 0.5f && length(c.up) > 0.5f && length(cross(c.forward, c.up)) > 0.5f;
}

Camera placeCamera(Camera lens, const Transform& world, const Vec3d& worldOrigin) {
    lens.position = Vec3f(world.applyPoint(Vec3d(0.0)) - worldOrigin);
    lens.forward = Vec3f(normalize(world.applyVector(Vec3d(0, 0, -1))));
    lens.up = Vec3f(normalize(world.applyVector(Vec3d(0, 1, 0))));
    return lens;
}

CameraRay cameraRay(const Camera& c, float x, float y, int width, int height) {
    const Vec3f right = normalize(cross(c.forward, c.up));
    const Vec3f up = cross(right, c.forward);
    const float aspect = float(width) / float(height);
    // Image position in [-1, 1]² (y up), scaled to the view's half extents.
    const float u = (2 * x / float(width) - 1) * aspect, v = 1 - 2 * y / float(height);
    if (c.projection == Projection::Orthographic)
        return {c.position + right * (u * c.ymag) + up * (v * c.ymag), c.forward};
    const float tanHalf = std::tan(c.yfov / 2);
    return {c.position, normalize(c.forward + right * (u * tanHalf) + up * (v * tanHalf))};
}

}  // namespace qsgi
