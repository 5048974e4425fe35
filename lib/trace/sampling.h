// Warping uniform numbers to the directions and points photon emission and scattering need.
#pragma once

#include <cmath>

#include "util/vecmath.h"

namespace qsgi {

constexpr float kPi = 3.14159265358979323846f;

// Cosine-weighted direction about unit normal n (pdf cosθ/π).
inline Vec3f cosineHemisphere(const Vec3f& n, float u0, float u1) {
    const float r = std::sqrt(u0), phi = 2 * kPi * u1;
    const float x = r * std::cos(phi), y = r * std::sin(phi), z = std::sqrt(std::max(0.0f, 1 - u0));
    Vec3f t, b;
    orthonormalBasis(n, t, b);
    return normalize(t * x + b * y + n * z);
}

// Uniform direction in the cone of half-angle acos(cosMax) about unit axis a.
inline Vec3f uniformCone(const Vec3f& a, float cosMax, float u0, float u1) {
    const float cosTheta = 1 - u0 * (1 - cosMax);
    const float sinTheta = std::sqrt(std::max(0.0f, 1 - cosTheta * cosTheta));
    const float phi = 2 * kPi * u1;
    Vec3f t, b;
    orthonormalBasis(a, t, b);
    return normalize(t * (sinTheta * std::cos(phi)) + b * (sinTheta * std::sin(phi)) + a * cosTheta);
}

inline Vec3f uniformSphere(float u0, float u1) {
    const float z = 1 - 2 * u0, r = std::sqrt(std::max(0.0f, 1 - z * z)), phi = 2 * kPi * u1;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Uniform barycentrics on a triangle (square-root parameterisation).
inline void uniformTriangle(float u0, float u1, float& b1, float& b2) {
    const float s = std::sqrt(u0);
    b1 = 1 - s;
    b2 = u1 * s;
}

// Uniform point in the unit disc (polar).
inline void uniformDisc(float u0, float u1, float& x, float& y) {
    const float r = std::sqrt(u0), phi = 2 * kPi * u1;
    x = r * std::cos(phi);
    y = r * std::sin(phi);
}

}  // namespace qsgi
