#include "scene/keyframes.h"

#include <algorithm>
#include <cmath>

namespace qsgi {

const char* interpolationName(Interpolation i) {
    switch (i) {
        case Interpolation::Step: return "STEP";
        case Interpolation::Linear: return "LINEAR";
        case Interpolation::CubicSpline: return "CUBICSPLINE";
    }
    return "?";
}

std::string trsDecompositionProblem(const Transform& t) {
    if (t.at(3, 0) != 0 || t.at(3, 1) != 0 || t.at(3, 2) != 0 || t.at(3, 3) != 1)
        return "has a last row other than 0 0 0 1, so it is no translation, rotation and scale (glTF requires that it "
               "decompose to them)";
    for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
            const Vec3d ca(t.at(0, a), t.at(1, a), t.at(2, a)), cb(t.at(0, b), t.at(1, b), t.at(2, b));
            if (std::fabs(dot(ca, cb)) > 1e-4 * length(ca) * length(cb))
                return "shears (its columns " + std::to_string(a) + " and " + std::to_string(b) +
                       " are not perpendicular), so it does not decompose to translation, rotation and scale";
        }
    return "";
}

NodeTrs decomposeTrs(const Transform& t) {
    NodeTrs trs;
    trs.translation = Vec3d(t.at(0, 3), t.at(1, 3), t.at(2, 3));
    Vec3d axis[3];
    int zero = 0;
    for (int c = 0; c < 3; ++c) {
        const Vec3d column(t.at(0, c), t.at(1, c), t.at(2, c));
        trs.scale[c] = length(column);
        axis[c] = trs.scale[c] > 0 ? column / trs.scale[c] : Vec3d(0.0);
        zero += trs.scale[c] > 0 ? 0 : 1;
    }
    // A flattened axis (scale 0) takes the direction that completes the others to a rotation, so
    // the rotation stays that of the axes that remain.
    if (zero == 3) axis[0] = Vec3d(1, 0, 0);
    for (int c = 0; zero >= 2 && c < 3; ++c)
        if (length(axis[c]) > 0) {
            const Vec3d a = axis[c];
            const Vec3d helper = std::fabs(a.x) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
            axis[(c + 1) % 3] = normalize(cross(a, helper));
            axis[(c + 2) % 3] = cross(a, axis[(c + 1) % 3]);
            break;
        }
    if (zero == 1)
        for (int c = 0; c < 3; ++c)
            if (!(length(axis[c]) > 0)) axis[c] = normalize(cross(axis[(c + 1) % 3], axis[(c + 2) % 3]));
    if (dot(cross(axis[0], axis[1]), axis[2]) < 0) {
        trs.scale.x = -trs.scale.x;
        axis[0] = -axis[0];
    }
    // The rotation matrix's quaternion (Shepperd's method: divide by the largest of the four
    // candidates, so no square root of a small difference decides the result).
    const double r00 = axis[0].x, r11 = axis[1].y, r22 = axis[2].z;
    const double r01 = axis[1].x, r10 = axis[0].y, r02 = axis[2].x, r20 = axis[0].z, r12 = axis[2].y, r21 = axis[1].z;
    const double trace = r00 + r11 + r22;
    std::array<double, 4> q;
    if (trace > 0) {
        const double s = 2 * std::sqrt(1 + trace);
        q = {(r21 - r12) / s, (r02 - r20) / s, (r10 - r01) / s, s / 4};
    } else if (r00 > r11 && r00 > r22) {
        const double s = 2 * std::sqrt(1 + r00 - r11 - r22);
        q = {s / 4, (r01 + r10) / s, (r02 + r20) / s, (r21 - r12) / s};
    } else if (r11 > r22) {
        const double s = 2 * std::sqrt(1 + r11 - r00 - r22);
        q = {(r01 + r10) / s, s / 4, (r12 + r21) / s, (r02 - r20) / s};
    } else {
        const double s = 2 * std::sqrt(1 + r22 - r00 - r11);
        q = {(r02 + r20) / s, (r12 + r21) / s, s / 4, (r10 - r01) / s};
    }
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& c : q) c /= n;
    trs.rotation = q;
    return trs;
}

const char* animatedPropertyName(AnimatedProperty p) {
    switch (p) {
        case AnimatedProperty::Translation: return "translation";
        case AnimatedProperty::Rotation: return "rotation";
        case AnimatedProperty::Scale: return "scale";
        case AnimatedProperty::Weights: return "weights";
    }
    return "?";
}

namespace {
using Quat = std::array<double, 4>;

double dot4(const Quat& a, const Quat& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]; }

Quat normalised(Quat q) {
    const double n = std::sqrt(dot4(q, q));
    if (!(n > 0)) return {0, 0, 0, 1};
    for (double& c : q) c /= n;
    return q;
}
}  // namespace

Quat slerp(const Quat& a, const Quat& bIn, double t) {
    Quat b = bIn;
    double d = dot4(a, b);
    if (d < 0) {  // q and −q are one rotation: go the shorter way
        for (double& c : b) c = -c;
        d = -d;
    }
    Quat out;
    if (d > 1 - 1e-9) {  // nearly equal: sin θ ≈ 0, the chord is the arc
        for (int c = 0; c < 4; ++c) out[c] = a[c] + t * (b[c] - a[c]);
        return normalised(out);
    }
    const double theta = std::acos(std::min(d, 1.0));
    const double wa = std::sin((1 - t) * theta) / std::sin(theta), wb = std::sin(t * theta) / std::sin(theta);
    for (int c = 0; c < 4; ++c) out[c] = wa * a[c] + wb * b[c];
    return normalised(out);
}

void KeyframeTrack::sample(double time, bool isRotation, double* out) const {
    const size_t keys = times.size();
    const int n = components;
    // Key k's value: for CUBICSPLINE the middle of its (in-tangent, value, out-tangent) triple.
    const size_t group = interpolation == Interpolation::CubicSpline ? 3 : 1;
    auto value = [&](size_t k) { return &values[(k * group + (group == 3 ? 1 : 0)) * size_t(n)]; };
    auto finish = [&] {
        if (!isRotation) return;
        Quat q{out[0], out[1], out[2], out[3]};
        q = normalised(q);
        std::copy(q.begin(), q.end(), out);
    };
    if (keys == 0) return;
    if (keys == 1 || !(time > times.front())) {  // before the first key (or NaN): clamp
        std::copy(value(0), value(0) + n, out);
        return finish();
    }
    if (time >= times.back()) {
        std::copy(value(keys - 1), value(keys - 1) + n, out);
        return finish();
    }
    // The key interval [t_k, t_k+1) holding `time`.
    const size_t k = size_t(std::upper_bound(times.begin(), times.end(), time) - times.begin()) - 1;
    const double td = times[k + 1] - times[k], s = (time - times[k]) / td;
    switch (interpolation) {
        case Interpolation::Step: std::copy(value(k), value(k) + n, out); break;
        case Interpolation::Linear:
            if (isRotation) {
                const double* a = value(k);
                const double* b = value(k + 1);
                const Quat q = slerp({a[0], a[1], a[2], a[3]}, {b[0], b[1], b[2], b[3]}, s);
                std::copy(q.begin(), q.end(), out);
            } else {
                for (int c = 0; c < n; ++c) out[c] = value(k)[c] + s * (value(k + 1)[c] - value(k)[c]);
            }
            break;
        case Interpolation::CubicSpline: {
            // Hermite spline (glTF 2.0 Appendix C): v_k, out-tangent b_k, in-tangent a_k+1, v_k+1,
            // tangents scaled by the interval's length.
            const double* outTangent = &values[(k * 3 + 2) * size_t(n)];
            const double* inTangent = &values[((k + 1) * 3 + 0) * size_t(n)];
            const double s2 = s * s, s3 = s2 * s;
            const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
            for (int c = 0; c < n; ++c)
                out[c] = h00 * value(k)[c] + td * h10 * outTangent[c] + h01 * value(k + 1)[c] + td * h11 * inTangent[c];
            break;
        }
    }
    finish();
}

void KeyframeAnimation::apply(double time, std::vector<NodeTrs>& nodes) const {
    double v[4];
    for (const AnimationChannel& c : channels) {
        NodeTrs& trs = nodes[size_t(c.node)];
        switch (c.property) {
            case AnimatedProperty::Translation:
                c.track.sample(time, false, v);
                trs.translation = Vec3d(v[0], v[1], v[2]);
                break;
            case AnimatedProperty::Rotation:
                c.track.sample(time, true, v);
                trs.rotation = {v[0], v[1], v[2], v[3]};
                break;
            case AnimatedProperty::Scale:
                c.track.sample(time, false, v);
                trs.scale = Vec3d(v[0], v[1], v[2]);
                break;
            case AnimatedProperty::Weights: break;  // morph weights deform meshes, not nodes
        }
    }
}

}  // namespace qsgi
