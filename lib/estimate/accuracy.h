// Accuracy of one vertex solution against a reference (usually a high-photon run of the same
// scene): relative RMS error and mean bias, overall and near borders, for the speed/accuracy
// trade that photon count and radius buy.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include "scene/scene.h"
#include "util/vecmath.h"

namespace qsgi {

struct ErrorStats {
    size_t vertices = 0;
    double relativeRms = 0;   // sqrt(mean |a − b|²) / mean |b|, over vertices and RGB channels
    double relativeBias = 0;  // mean (a − b) / mean |b|
};

struct AccuracyReport {
    ErrorStats all;
    ErrorStats edge;      // vertices on an edge of their surface (a border or a crease of more than 45°)
    ErrorStats nearEdge;  // within one radius of an edge, not on one
    ErrorStats interior;  // the rest
    // Vertices where two surfaces touch (touchingOtherSurfaces): a block standing on a floor, a
    // wall's foot. Across the others, not one of their partition: what a vertex there should be
    // is the limit of two surfaces at once, and references disagree most there.
    ErrorStats contact;
};

// Vertices within `tolerance` of a triangle that is not one of theirs (vertices welded by
// position): where one surface rests on or runs into another.
std::vector<bool> touchingOtherSurfaces(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles,
                                        float tolerance);

enum class EdgeRegion : uint8_t { OnEdge, NearEdge, Interior };

// Region of every vertex: on an edge (an edge of its surface used by one triangle, by more than
// two, or by two whose front faces turn by more than 45°; vertices welded by position), within
// `radius` of such an edge (distance to the edge segments, exact to radius/16), or interior.
std::vector<EdgeRegion> edgeRegions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                    const std::vector<Triangle>& triangles, float radius);

// Vertices near a crease: within `distance` of a vertex whose normal turns by more than 30°
// from theirs (inside corners, convex edges, silhouettes).
std::vector<bool> verticesNearCreases(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      float distance);

// What ErrorStats and the surface's figures (surface_accuracy.h) are made from: each value against
// its reference, channel by channel, in the order added; the figures relative to the reference's
// mean |·| (absolute where that mean is 0).
struct RelativeErrorSums {
    double squared = 0, difference = 0, reference = 0;
    size_t count = 0;  // values added (three channels each)
    void add(const Vec3f& value, const Vec3f& referenceValue) {
        for (int c = 0; c < 3; ++c) {
            const double d = double(value[c]) - double(referenceValue[c]);
            squared += d * d;
            difference += d;
            reference += std::fabs(double(referenceValue[c]));
        }
        ++count;
    }
    double channels() const { return 3.0 * double(count); }
    double scale() const { return reference / channels() > 0 ? reference / channels() : 1.0; }
    double relativeRms() const { return std::sqrt(squared / channels()) / scale(); }
    double relativeBias() const { return difference / channels() / scale(); }
};

ErrorStats errorStats(const std::vector<Vec3f>& values, const std::vector<Vec3f>& reference,
                      const std::vector<bool>& subset = {});

// `only`, if not empty: the vertices the reference holds (a vertex subset's reference); the
// regions are decided on the whole mesh and each counts only these.
AccuracyReport compareSolutions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                const std::vector<Vec3f>& reference, float radius, const std::vector<bool>& only = {});

}  // namespace qsgi
