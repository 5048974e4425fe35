#include "util/vecmath.h"

namespace qsgi {

float Bounds3f::exitDistance(const Vec3f& o, const Vec3f& d) const {
    if (empty()) return 0;
    float tfar = std::numeric_limits<float>::max();
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) continue;
        const float t0 = (lower[a] - o[a]) / d[a];
        const float t1 = (upper[a] - o[a]) / d[a];
        tfar = std::min(tfar, std::max(t0, t1));
    }
    return std::isfinite(tfar) && tfar < std::numeric_limits<float>::max() ? std::max(0.0f, tfar) : 0.0f;
}

bool Bounds3f::clip(const Vec3f& o, const Vec3f& d, double& t0, double& t1) const {
    if (empty()) return false;
    for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
            if (o[a] < lower[a] || o[a] > upper[a]) return false;
            continue;
        }
        double ta = (double(lower[a]) - double(o[a])) / double(d[a]);
        double tb = (double(upper[a]) - double(o[a])) / double(d[a]);
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    return true;
}

Transform Transform::fromTRS(const Vec3d& t, const std::array<double, 4>& q, const Vec3d& s) {
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    // Rotation matrix of a unit quaternion; normalise first so slightly-off inputs stay rigid.
    const double n = std::sqrt(x * x + y * y + z * z + w * w);
    const double qx = n > 0 ? x / n : 0, qy = n > 0 ? y / n : 0, qz = n > 0 ? z / n : 0, qw = n > 0 ? w / n : 1;
    const double r[3][3] = {
        {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)},
        {2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)},
        {2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)}};
    Transform out;
    for (int row = 0; row < 3; ++row)
        for (int col = 0; col < 3; ++col) out.at(row, col) = r[row][col] * s[col];
    out.at(0, 3) = t.x;
    out.at(1, 3) = t.y;
    out.at(2, 3) = t.z;
    return out;
}

Transform Transform::operator*(const Transform& o) const {
    Transform r;
    for (int row = 0; row < 4; ++row)
        for (int col = 0; col < 4; ++col) {
            double sum = 0;
            for (int k = 0; k < 4; ++k) sum += at(row, k) * o.at(k, col);
            r.at(row, col) = sum;
        }
    return r;
}

Vec3d Transform::applyPoint(const Vec3d& p) const {
    return {at(0, 0) * p.x + at(0, 1) * p.y + at(0, 2) * p.z + at(0, 3),
            at(1, 0) * p.x + at(1, 1) * p.y + at(1, 2) * p.z + at(1, 3),
            at(2, 0) * p.x + at(2, 1) * p.y + at(2, 2) * p.z + at(2, 3)};
}

Vec3d Transform::applyVector(const Vec3d& v) const {
    return {at(0, 0) * v.x + at(0, 1) * v.y + at(0, 2) * v.z,
            at(1, 0) * v.x + at(1, 1) * v.y + at(1, 2) * v.z,
            at(2, 0) * v.x + at(2, 1) * v.y + at(2, 2) * v.z};
}

double Transform::determinant3x3() const {
    return at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) -
           at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0)) +
           at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
}

bool Transform::isInvertible() const {
    if (!isFinite()) return false;
    double columns = 1;
    for (int c = 0; c < 3; ++c) columns *= std::sqrt(at(0, c) * at(0, c) + at(1, c) * at(1, c) + at(2, c) * at(2, c));
    return columns > 0 && std::fabs(determinant3x3()) > 1e-9 * columns;
}

Transform Transform::normalMatrix() const {
    // inverse-transpose of the 3x3 = cofactor matrix / det
    const double det = determinant3x3();
    Transform r;
    const double inv = det != 0 ? 1.0 / det : 0.0;
    r.at(0, 0) = (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) * inv;
    r.at(0, 1) = (at(1, 2) * at(2, 0) - at(1, 0) * at(2, 2)) * inv;
    r.at(0, 2) = (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0)) * inv;
    r.at(1, 0) = (at(0, 2) * at(2, 1) - at(0, 1) * at(2, 2)) * inv;
    r.at(1, 1) = (at(0, 0) * at(2, 2) - at(0, 2) * at(2, 0)) * inv;
    r.at(1, 2) = (at(0, 1) * at(2, 0) - at(0, 0) * at(2, 1)) * inv;
    r.at(2, 0) = (at(0, 1) * at(1, 2) - at(0, 2) * at(1, 1)) * inv;
    r.at(2, 1) = (at(0, 2) * at(1, 0) - at(0, 0) * at(1, 2)) * inv;
    r.at(2, 2) = (at(0, 0) * at(1, 1) - at(0, 1) * at(1, 0)) * inv;
    return r;
}

bool Transform::isFinite() const {
    for (double v : m)
        if (!std::isfinite(v)) return false;
    return true;
}

}  // namespace qsgi
