// Keyframed animation as glTF 2.0 defines it (§3.11 and Appendix C): channels that drive a node's
// translation, rotation, scale or morph weights from a sampler of key times and values, with STEP,
// LINEAR (spherical for rotations) and CUBICSPLINE (Hermite) interpolation, clamped to the first
// and last key outside their span. Pure data and arithmetic: the glTF reader fills it
// (gltf_animation.h), Animation samples it per frame (animation.h).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

enum class Interpolation { Step, Linear, CubicSpline };
enum class AnimatedProperty { Translation, Rotation, Scale, Weights };

const char* interpolationName(Interpolation i);
const char* animatedPropertyName(AnimatedProperty p);

// One sampler: key times (seconds, strictly increasing) and, per key, `components` values; for
// CUBICSPLINE three groups per key: in-tangent, value, out-tangent (glTF's layout).
struct KeyframeTrack {
    Interpolation interpolation = Interpolation::Linear;
    int components = 0;
    std::vector<double> times;
    std::vector<double> values;

    // The track's value at `time` into out[0..components). Rotations (quaternions x, y, z, w) are
    // interpolated along the shorter arc and returned normalised.
    void sample(double time, bool isRotation, double* out) const;
};

struct AnimationChannel {
    int node = -1;
    AnimatedProperty property = AnimatedProperty::Translation;
    KeyframeTrack track;
};

// A node's local transform as glTF's separate properties, which channels replace one at a time.
struct NodeTrs {
    Vec3d translation{0.0};
    std::array<double, 4> rotation{0, 0, 0, 1};  // x, y, z, w
    Vec3d scale{1.0};
    Transform matrix() const { return Transform::fromTRS(translation, rotation, scale); }
};

// glTF 2.0 (§5.25, node.matrix): why a node's matrix does not decompose to translation, rotation
// and scale — a last row other than 0 0 0 1, or a shear (two of its first three columns not
// perpendicular) — or "" when it does. The glTF loader refuses such a node's matrix and a
// transform file such a node's entry, with these words.
std::string trsDecompositionProblem(const Transform& matrix);
// The translation, rotation and scale of a matrix that decomposes (trsDecompositionProblem is
// ""): a mirror goes into the scale's x, so the rotation is proper. A zero column gets scale 0
// and, where the rotation cannot be told, the identity's axis.
NodeTrs decomposeTrs(const Transform& matrix);

struct KeyframeAnimation {
    std::string name;
    std::vector<AnimationChannel> channels;
    double startTime = 0, endTime = 0;  // the span of every channel's keys

    // `rest` (one per node) with every channel of this animation applied at `time`.
    void apply(double time, std::vector<NodeTrs>& rest) const;
};

// Spherical linear interpolation of unit quaternions (x, y, z, w) along the shorter arc.
std::array<double, 4> slerp(const std::array<double, 4>& a, const std::array<double, 4>& b, double t);

}  // namespace qsgi
