#include "estimate/accuracy.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "estimate/own_surface.h"
#include "estimate/point_index.h"
#include "scene/mesh_topology.h"

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

std::vector<EdgeRegion> edgeRegions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                    const std::vector<Triangle>& triangles, float radius) {
    const MeshTopology topology(positions, triangles);
    auto front = [&](uint32_t t) { return frontFaceNormal(positions, normals, triangles[t]); };
    // Every edge (pair of welded ids) with the triangles that use it.
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> users;
    for (uint32_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = topology.weldedId(triangles[t].v[k]), b = topology.weldedId(triangles[t].v[(k + 1) % 3]);
            if (a == b) continue;
            users[std::minmax(a, b)].push_back(t);
        }
    std::vector<uint8_t> onEdge(positions.size(), 0);
    std::vector<Vec3f> edgeSamples;
    for (const auto& [edge, tris] : users) {
        bool isEdge = tris.size() != 2;
        // A crease turns by more than the own surface's 45° limit.
        if (!isEdge) isEdge = dot(front(tris[0]), front(tris[1])) < kOwnSurfaceCos;
        if (!isEdge) continue;
        onEdge[edge.first] = onEdge[edge.second] = 1;
        // Points along the segment every radius/8: distances to it are then exact to radius/16.
        const Vec3f a = positions[edge.first], b = positions[edge.second];
        const int steps = std::max(1, int(std::ceil(length(b - a) / (radius / 8))));
        for (int i = 0; i <= steps; ++i) edgeSamples.push_back(a + (b - a) * (float(i) / float(steps)));
    }
    std::vector<EdgeRegion> region(positions.size(), EdgeRegion::Interior);
    const PointIndex index(edgeSamples);
    std::vector<size_t> found;
    std::vector<float> d2;
    for (size_t v = 0; v < positions.size(); ++v) {
        if (onEdge[topology.weldedId(uint32_t(v))]) {
            region[v] = EdgeRegion::OnEdge;
            continue;
        }
        if (!(radius > 0) || edgeSamples.empty()) continue;
        index.nearest(positions[v], 1, found, d2);
        if (!found.empty() && d2[0] <= radius * radius) region[v] = EdgeRegion::NearEdge;
    }
    return region;
}

AccuracyReport compareSolutions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                const std::vector<Vec3f>& reference, float radius) {
    AccuracyReport r;
    r.all = errorStats(values, reference);
    const std::vector<EdgeRegion> region = edgeRegions(positions, normals, triangles, radius);
    auto subset = [&](EdgeRegion which) {
        std::vector<bool> in(region.size());
        for (size_t v = 0; v < region.size(); ++v) in[v] = region[v] == which;
        return in;
    };
    r.edge = errorStats(values, reference, subset(EdgeRegion::OnEdge));
    r.nearEdge = errorStats(values, reference, subset(EdgeRegion::NearEdge));
    r.interior = errorStats(values, reference, subset(EdgeRegion::Interior));
    return r;
}

}  // namespace qsgi
