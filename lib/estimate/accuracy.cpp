#include "estimate/accuracy.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

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

namespace {

// Squared distance from p to the triangle abc (closest point by regions, Ericson §5.1.5).
double squaredDistanceToTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    auto d2to = [&](const Vec3d& q) { return dot(p - q, p - q); };
    if (d1 <= 0 && d2 <= 0) return d2to(a);
    const Vec3d bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return d2to(b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return d2to(a + ab * (d1 / (d1 - d3)));
    const Vec3d cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return d2to(c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return d2to(a + ac * (d2 / (d2 - d6)));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return d2to(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    const double denom = va + vb + vc;
    if (!(denom != 0)) return d2to(a);
    return d2to(a + ab * (vb / denom) + ac * (vc / denom));
}

}  // namespace

std::vector<bool> touchingOtherSurfaces(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles,
                                        float tolerance) {
    std::vector<bool> touching(positions.size(), false);
    if (positions.empty() || triangles.empty()) return touching;
    const MeshTopology topology(positions, triangles);
    // A uniform grid of cells about a mean triangle across, each listing the triangles whose
    // bounds (padded by the tolerance) overlap it.
    Bounds3f bounds;
    double meanSize = 0;
    for (const Triangle& t : triangles) {
        Bounds3f b;
        for (uint32_t v : t.v) b.extend(positions[v]);
        bounds.extend(b);
        meanSize += double(maxComponent(b.diagonal()));
    }
    meanSize /= double(triangles.size());
    const double extent = std::max(double(maxComponent(bounds.diagonal())), 1e-30);
    const double cell = std::max({meanSize, double(tolerance), extent / 1024.0});
    auto cellOf = [&](double x, int axis) { return int64_t(std::floor((x - double(bounds.lower[axis])) / cell)); };
    auto key = [](int64_t x, int64_t y, int64_t z) { return uint64_t(x & 0x1FFFFF) << 42 | uint64_t(y & 0x1FFFFF) << 21 | uint64_t(z & 0x1FFFFF); };
    std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        Bounds3f b;
        for (uint32_t v : triangles[t].v) b.extend(positions[v]);
        b = b.expanded(tolerance);
        for (int64_t x = cellOf(b.lower.x, 0); x <= cellOf(b.upper.x, 0); ++x)
            for (int64_t y = cellOf(b.lower.y, 1); y <= cellOf(b.upper.y, 1); ++y)
                for (int64_t z = cellOf(b.lower.z, 2); z <= cellOf(b.upper.z, 2); ++z) grid[key(x, y, z)].push_back(t);
    }
    const double tolerance2 = double(tolerance) * double(tolerance);
    for (uint32_t v = 0; v < positions.size(); ++v) {
        const Vec3d p(positions[v]);
        const auto it = grid.find(key(cellOf(p.x, 0), cellOf(p.y, 1), cellOf(p.z, 2)));
        if (it == grid.end()) continue;
        for (uint32_t t : it->second) {
            // Its own triangles (at its welded position) do not count.
            if (std::binary_search(topology.trianglesBegin(v), topology.trianglesEnd(v), t)) continue;
            const Triangle& tri = triangles[t];
            if (squaredDistanceToTriangle(p, Vec3d(positions[tri.v[0]]), Vec3d(positions[tri.v[1]]), Vec3d(positions[tri.v[2]])) <=
                tolerance2) {
                touching[v] = true;
                break;
            }
        }
    }
    return touching;
}

AccuracyReport compareSolutions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                const std::vector<Vec3f>& reference, float radius, const std::vector<bool>& only) {
    AccuracyReport r;
    auto within = [&](std::vector<bool> in) {
        if (only.empty()) return in;
        for (size_t v = 0; v < in.size(); ++v) in[v] = in[v] && v < only.size() && only[v];
        return in;
    };
    r.all = errorStats(values, reference, only);
    const std::vector<EdgeRegion> region = edgeRegions(positions, normals, triangles, radius);
    auto subset = [&](EdgeRegion which) {
        std::vector<bool> in(region.size());
        for (size_t v = 0; v < region.size(); ++v) in[v] = region[v] == which;
        return within(std::move(in));
    };
    r.edge = errorStats(values, reference, subset(EdgeRegion::OnEdge));
    r.nearEdge = errorStats(values, reference, subset(EdgeRegion::NearEdge));
    r.interior = errorStats(values, reference, subset(EdgeRegion::Interior));
    // Touching: within 10^-5 of the scene's size of another surface (the scenes' contacts are
    // exact; a tolerance keeps float rounding of placed meshes from hiding them).
    Bounds3f bounds;
    for (const Vec3f& p : positions) bounds.extend(p);
    r.contact = errorStats(values, reference, within(touchingOtherSurfaces(positions, triangles, 1e-5f * bounds.extent())));
    return r;
}

}  // namespace qsgi
