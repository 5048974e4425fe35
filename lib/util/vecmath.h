// Small value types for geometry: 3-vectors and 4x4 affine transforms.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace qsgi {

template <typename T>
struct Vec3 {
    T x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    constexpr explicit Vec3(T v) : x(v), y(v), z(v) {}
    template <typename U>
    constexpr explicit Vec3(const Vec3<U>& o) : x(T(o.x)), y(T(o.y)), z(T(o.z)) {}

    constexpr T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3 operator*(const Vec3& o) const { return {x * o.x, y * o.y, z * o.z}; }
    Vec3& operator+=(const Vec3& o) { x += o.x; y += o.y; z += o.z; return *this; }
    Vec3& operator-=(const Vec3& o) { x -= o.x; y -= o.y; z -= o.z; return *this; }
    Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
    constexpr bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
    constexpr bool operator!=(const Vec3& o) const { return !(*this == o); }
};

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <typename T> constexpr Vec3<T> operator*(T s, const Vec3<T>& v) { return v * s; }
template <typename T> constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
template <typename T> constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T> T length(const Vec3<T>& v) { return std::sqrt(dot(v, v)); }
template <typename T> Vec3<T> normalize(const Vec3<T>& v) {
    T len = length(v);
    return len > T(0) ? v / len : Vec3<T>(0, 0, 0);
}
template <typename T> constexpr T maxComponent(const Vec3<T>& v) { return std::max(v.x, std::max(v.y, v.z)); }
template <typename T> constexpr Vec3<T> min(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
template <typename T> constexpr Vec3<T> max(const Vec3<T>& a, const Vec3<T>& b) {
    return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
template <typename T> bool isFinite(const Vec3<T>& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
// Rec. 709 luminance: the weight lights are chosen by (docs/design.md §4).
template <typename T> constexpr T luminance(const Vec3<T>& c) {
    return T(0.2126) * c.x + T(0.7152) * c.y + T(0.0722) * c.z;
}

// Orthonormal basis around a unit vector (Duff et al. 2017, branchless).
template <typename T>
inline void orthonormalBasis(const Vec3<T>& n, Vec3<T>& t, Vec3<T>& b) {
    T sign = std::copysign(T(1), n.z);
    T a = T(-1) / (sign + n.z);
    T c = n.x * n.y * a;
    t = {T(1) + sign * n.x * n.x * a, sign * c, -sign * n.x};
    b = {c, sign + n.y * n.y * a, -n.y};
}

struct Bounds3f {
    Vec3f lower{std::numeric_limits<float>::max()};
    Vec3f upper{-std::numeric_limits<float>::max()};

    bool empty() const { return lower.x > upper.x; }
    bool operator==(const Bounds3f& o) const { return lower == o.lower && upper == o.upper; }
    void extend(const Vec3f& p) { lower = min(lower, p); upper = max(upper, p); }
    Vec3f center() const { return (lower + upper) * 0.5f; }
    Vec3f diagonal() const { return empty() ? Vec3f(0) : upper - lower; }
    float extent() const { return length(diagonal()); }
    void extend(const Bounds3f& b) {
        if (!b.empty()) { extend(b.lower); extend(b.upper); }
    }
    Bounds3f expanded(float margin) const {
        if (empty()) return *this;
        Bounds3f b = *this;
        b.lower = lower - Vec3f(margin);
        b.upper = upper + Vec3f(margin);
        return b;
    }
    bool contains(const Vec3f& p) const {
        return lower.x <= p.x && p.x <= upper.x && lower.y <= p.y && p.y <= upper.y && lower.z <= p.z && p.z <= upper.z;
    }
    bool overlaps(const Bounds3f& b) const {
        return !empty() && !b.empty() && lower.x <= b.upper.x && b.lower.x <= upper.x && lower.y <= b.upper.y &&
               b.lower.y <= upper.y && lower.z <= b.upper.z && b.lower.z <= upper.z;
    }
    // Distance along the ray o + t·d (d ≠ 0) to where it leaves the box; 0 if it starts outside
    // and never enters or the box is empty. Escaping photons end there (docs/design.md §4, §5).
    float exitDistance(const Vec3f& o, const Vec3f& d) const;
    // Clips the part [t0, t1] of the ray o + t·d to the box (in double precision, closed box);
    // false if it misses. t1 may be infinite.
    bool clip(const Vec3f& o, const Vec3f& d, double& t0, double& t1) const;
    // Whether the part [0, end] of the ray o + t·d meets the box (end may be infinite).
    bool meetsRay(const Vec3f& o, const Vec3f& d, double end) const {
        double t0 = 0, t1 = end;
        return clip(o, d, t0, t1);
    }
    // Largest coordinate magnitude: what limits float precision of positions.
    float maxAbsCoordinate() const {
        if (empty()) return 0;
        return std::max(maxComponent(Vec3f(std::fabs(lower.x), std::fabs(lower.y), std::fabs(lower.z))),
                        maxComponent(Vec3f(std::fabs(upper.x), std::fabs(upper.y), std::fabs(upper.z))));
    }
};

// Whether the part [0, end] of the ray o + t·d meets any of the boxes: the test every segment-
// against-movers question asks (the envelope, the blocking rule's candidates, the fallback's count).
inline bool rayMeetsAny(const std::vector<Bounds3f>& boxes, const Vec3f& o, const Vec3f& d, double end) {
    for (const Bounds3f& b : boxes)
        if (b.meetsRay(o, d, end)) return true;
    return false;
}

// Column-major 4x4 affine transform in double precision (glTF's layout).
struct Transform {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    static Transform fromColumnMajor(const double* values) {
        Transform t;
        std::copy(values, values + 16, t.m.begin());
        return t;
    }
    // T * R * S with quaternion rotation (x, y, z, w), as glTF composes them.
    static Transform fromTRS(const Vec3d& translation, const std::array<double, 4>& rotation, const Vec3d& scale);

    double at(int row, int col) const { return m[col * 4 + row]; }
    double& at(int row, int col) { return m[col * 4 + row]; }

    Transform operator*(const Transform& o) const;
    Vec3d applyPoint(const Vec3d& p) const;
    Vec3d applyVector(const Vec3d& v) const;
    double determinant3x3() const;
    // Finite, and its 3x3 not degenerate relative to its own scale: |det| against the product of
    // its column lengths (1 for any rotation times any scale, 0 for a flattened one), so a scale
    // of 1e-5 is as invertible as a scale of 1.
    bool isInvertible() const;
    // The inverse-transpose of the upper 3x3, for normals. Requires an invertible transform.
    Transform normalMatrix() const;
    bool isFinite() const;
    bool operator==(const Transform& o) const { return m == o.m; }
};

}  // namespace qsgi
