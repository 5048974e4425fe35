#include "scene/camera.h"

#include <cmath>
#include <stdexcept>

namespace qsgi {

PerspectiveCamera lookAtCamera(const Vec3f& position, const Vec3f& target, const Vec3f& up, float yfov) {
    PerspectiveCamera c;
    c.position = position;
    c.forward = normalize(target - position);
    c.up = normalize(up);
    c.yfov = yfov;
    if (dot(c.forward, c.forward) == 0) throw std::invalid_argument("position and target coincide");
    if (length(cross(c.forward, c.up)) < 1e-6f) throw std::invalid_argument("up is parallel to the view direction");
    if (!(yfov > 0 && yfov < 3.1f)) throw std::invalid_argument("yfov must lie in (0, 3.1) radians");
    return c;
}

PerspectiveCamera framingCamera(const Bounds3f& bounds, float aspect) {
    const Vec3f centre = bounds.center();
    const float radius = std::max(0.5f * bounds.extent(), 1e-3f);
    const float yfov = 0.8f;
    // Distance at which the bounding sphere fits the narrower field of view.
    const float halfFov = std::min(yfov, 2 * std::atan(std::tan(yfov / 2) * std::max(aspect, 0.1f))) / 2;
    const float distance = radius / std::sin(halfFov);
    const Vec3f direction = normalize(Vec3f(0, 0.25f, 1));
    return lookAtCamera(centre + direction * distance, centre, Vec3f(0, 1, 0), yfov);
}

Vec3f cameraRayDirection(const PerspectiveCamera& c, float x, float y, int width, int height) {
    const Vec3f right = normalize(cross(c.forward, c.up));
    const Vec3f up = cross(right, c.forward);
    const float tanHalf = std::tan(c.yfov / 2);
    const float aspect = float(width) / float(height);
    const float sx = (2 * x / float(width) - 1) * tanHalf * aspect;
    const float sy = (1 - 2 * y / float(height)) * tanHalf;
    return normalize(c.forward + right * sx + up * sy);
}

}  // namespace qsgi
