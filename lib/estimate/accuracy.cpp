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
    std::vector<std::pair<Vec3f, Vec3f>> edges;
    double edgeLength = 0;
    for (const auto& [edge, tris] : users) {
        bool isEdge = tris.size() != 2;
        // A crease turns by more than the own surface's 45° limit.
        if (!isEdge) isEdge = dot(front(tris[0]), front(tris[1])) < kOwnSurfaceCos;
        if (!isEdge) continue;
        onEdge[edge.first] = onEdge[edge.second] = 1;
        edges.emplace_back(positions[edge.first], positions[edge.second]);
        edgeLength += length(edges.back().second - edges.back().first);
    }
    // Edges cut into pieces no longer than `piece`, indexed by their midpoints; a vertex is near an
    // edge when its exact distance to a piece is within the radius, and only pieces whose midpoint
    // lies within radius + piece/2 can be. The piece is at least the radius (few candidates per
    // vertex) and at least 2^-16 of all edges' length, so a radius of 1e-6 of the scene cannot
    // make hundreds of millions of pieces.
    const float piece = std::max(radius, float(edgeLength / double(1 << 16)));
    std::vector<std::pair<Vec3f, Vec3f>> pieces;
    std::vector<Vec3f> midpoints;
    for (const auto& [a, b] : edges) {
        const int count = piece > 0 ? std::max(1, int(std::ceil(length(b - a) / piece))) : 1;
        for (int i = 0; i < count; ++i) {
            const Vec3f p0 = a + (b - a) * (float(i) / float(count)), p1 = a + (b - a) * (float(i + 1) / float(count));
            pieces.emplace_back(p0, p1);
            midpoints.push_back((p0 + p1) * 0.5f);
        }
    }
    auto distanceSquaredToPiece = [&](const Vec3f& p, size_t i) {
        const auto& [a, b] = pieces[i];
        const Vec3f ab = b - a;
        const float t = std::clamp(dot(p - a, ab) / std::max(dot(ab, ab), 1e-30f), 0.0f, 1.0f);
        const Vec3f d = p - (a + ab * t);
        return dot(d, d);
    };
    std::vector<EdgeRegion> region(positions.size(), EdgeRegion::Interior);
    const PointIndex index(midpoints);
    std::vector<size_t> found;
    std::vector<float> d2;
    const float reach = radius + 0.5f * piece;
    for (size_t v = 0; v < positions.size(); ++v) {
        if (onEdge[topology.weldedId(uint32_t(v))]) {
            region[v] = EdgeRegion::OnEdge;
            continue;
        }
        if (!(radius > 0) || pieces.empty()) continue;
        // The nearest midpoint settles most vertices at once (a piece is never farther than its
        // midpoint); the others are decided by every piece that could reach.
        index.nearest(positions[v], 1, found, d2);
        bool near = distanceSquaredToPiece(positions[v], found[0]) <= radius * radius;
        if (!near) {
            index.withinRadius(positions[v], reach * reach, found, d2);
            for (size_t i : found)
                if ((near = distanceSquaredToPiece(positions[v], i) <= radius * radius)) break;
        }
        if (near) region[v] = EdgeRegion::NearEdge;
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
