#include "estimate/accuracy.h"

#include <cmath>

#include "estimate/point_index.h"

namespace qsgi {

std::vector<bool> verticesNearCreases(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      float distance) {
    std::vector<bool> near(positions.size(), false);
    if (!(distance > 0)) return near;
    const PointIndex index(positions);
    const float cosCrease = std::cos(30.0f * 3.14159265f / 180.0f);
    std::vector<size_t> found;
    std::vector<float> d2;
    for (size_t v = 0; v < positions.size(); ++v) {
        index.withinRadius(positions[v], distance * distance, found, d2);
        for (size_t w : found)
            if (dot(normals[v], normals[w]) < cosCrease) {
                near[v] = true;
                break;
            }
    }
    return near;
}

ErrorStats errorStats(const std::vector<Vec3f>& values, const std::vector<Vec3f>& reference, const std::vector<bool>& subset) {
    ErrorStats s;
    double sq = 0, diff = 0, ref = 0;
    for (size_t v = 0; v < values.size() && v < reference.size(); ++v) {
        if (!subset.empty() && !subset[v]) continue;
        for (int c = 0; c < 3; ++c) {
            const double d = double(values[v][c]) - double(reference[v][c]);
            sq += d * d;
            diff += d;
            ref += std::fabs(double(reference[v][c]));
        }
        ++s.vertices;
    }
    if (s.vertices == 0) return s;
    const double n = 3.0 * double(s.vertices);
    const double meanRef = ref / n;
    s.relativeRms = meanRef > 0 ? std::sqrt(sq / n) / meanRef : std::sqrt(sq / n);
    s.relativeBias = meanRef > 0 ? (diff / n) / meanRef : diff / n;
    return s;
}

AccuracyReport compareSolutions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                const std::vector<Vec3f>& values, const std::vector<Vec3f>& reference,
                                float borderDistance) {
    AccuracyReport r;
    r.all = errorStats(values, reference);
    if (borderDistance > 0) r.border = errorStats(values, reference, verticesNearCreases(positions, normals, borderDistance));
    return r;
}

}  // namespace qsgi
