// Accuracy of one vertex solution against a reference (usually a high-photon run of the same
// scene): relative RMS error and mean bias, overall and near borders, for the speed/accuracy
// trade that photon count and radius buy.
#pragma once

#include <cstddef>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

struct ErrorStats {
    size_t vertices = 0;
    double relativeRms = 0;   // sqrt(mean |a − b|²) / mean |b|, over vertices and RGB channels
    double relativeBias = 0;  // mean (a − b) / mean |b|
};

struct AccuracyReport {
    ErrorStats all;
    ErrorStats border;  // vertices within `borderDistance` of a crease (empty if distance is 0)
};

// Vertices near a crease: within `distance` of a vertex whose normal turns by more than 30°
// from theirs (inside corners, convex edges, silhouettes).
std::vector<bool> verticesNearCreases(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      float distance);

ErrorStats errorStats(const std::vector<Vec3f>& values, const std::vector<Vec3f>& reference,
                      const std::vector<bool>& subset = {});

AccuracyReport compareSolutions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                const std::vector<Vec3f>& values, const std::vector<Vec3f>& reference,
                                float borderDistance);

}  // namespace qsgi
