#include "estimate/mesh_bands.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "estimate/own_surface.h"

namespace qsgi {

MeshEdges::MeshEdges(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals, const std::vector<Triangle>& triangles,
                     const MeshTopology& topology, float radius)
    : topology_(topology), radius_(radius), onEdge_(positions.size(), 0) {
    auto front = [&](uint32_t t) { return frontFaceNormal(positions, normals, triangles[t]); };
    // Every edge (pair of welded ids) with the triangles that use it.
    std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> users;
    for (uint32_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = topology.weldedId(triangles[t].v[k]), b = topology.weldedId(triangles[t].v[(k + 1) % 3]);
            if (a == b) continue;
            users[std::minmax(a, b)].push_back(t);
        }
    std::vector<std::pair<Vec3f, Vec3f>> edges;
    double edgeLength = 0;
    for (const auto& [edge, tris] : users) {
        bool isEdge = tris.size() != 2;
        // A crease turns by more than the own surface's 45° limit.
        if (!isEdge) isEdge = dot(front(tris[0]), front(tris[1])) < kOwnSurfaceCos;
        if (!isEdge) continue;
        onEdge_[edge.first] = onEdge_[edge.second] = 1;
        edges.emplace_back(positions[edge.first], positions[edge.second]);
        edgeLength += length(edges.back().second - edges.back().first);
    }
    if (!(radius > 0) || edges.empty()) return;
    // Edges cut into pieces no longer than `piece`, indexed by their midpoints; a place is near an
    // edge when its exact distance to a piece is within the radius, and only pieces whose midpoint
    // lies within radius + piece/2 can be. The piece is at least the radius (few candidates per
    // place) and at least 2^-16 of all edges' length, so a radius of 1e-6 of the scene cannot
    // make hundreds of millions of pieces.
    const float piece = std::max(radius, float(edgeLength / double(1 << 16)));
    for (const auto& [a, b] : edges) {
        const int count = piece > 0 ? std::max(1, int(std::ceil(length(b - a) / piece))) : 1;
        for (int i = 0; i < count; ++i) {
            const Vec3f p0 = a + (b - a) * (float(i) / float(count)), p1 = a + (b - a) * (float(i + 1) / float(count));
            pieces_.emplace_back(p0, p1);
            midpoints_.push_back((p0 + p1) * 0.5f);
        }
    }
    reach_ = radius + 0.5f * piece;
    index_.emplace(midpoints_);
}

float MeshEdges::squaredDistanceToPiece(const Vec3f& p, size_t i) const {
    const auto& [a, b] = pieces_[i];
    const Vec3f ab = b - a;
    const float t = std::clamp(dot(p - a, ab) / std::max(dot(ab, ab), 1e-30f), 0.0f, 1.0f);
    const Vec3f d = p - (a + ab * t);
    return dot(d, d);
}

bool MeshEdges::within(const Vec3f& p) const {
    if (!index_) return false;
    std::vector<size_t> found;
    std::vector<float> d2;
    // The nearest midpoint settles most places at once (a piece is never farther than its
    // midpoint); the others are decided by every piece that could reach.
    const float r2 = radius_ * radius_;
    index_->nearest(p, 1, found, d2);
    if (squaredDistanceToPiece(p, found[0]) <= r2) return true;
    index_->withinRadius(p, reach_ * reach_, found, d2);
    for (size_t i : found)
        if (squaredDistanceToPiece(p, i) <= r2) return true;
    return false;
}

TriangleGrid::TriangleGrid(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, float reach) {
    if (triangles.empty()) return;
    double meanSize = 0;
    for (const Triangle& t : triangles) {
        Bounds3f b;
        for (uint32_t v : t.v) b.extend(positions[v]);
        bounds_.extend(b);
        meanSize += double(maxComponent(b.diagonal()));
    }
    meanSize /= double(triangles.size());
    const double extent = std::max(double(maxComponent(bounds_.diagonal())), 1e-30);
    cell_ = std::max({meanSize, double(reach), extent / 1024.0});
    auto cellOf = [&](double x, int axis) { return int64_t(std::floor((x - double(bounds_.lower[axis])) / cell_)); };
    for (uint32_t t = 0; t < triangles.size(); ++t) {
        Bounds3f b;
        for (uint32_t v : triangles[t].v) b.extend(positions[v]);
        b = b.expanded(reach);
        for (int64_t x = cellOf(b.lower.x, 0); x <= cellOf(b.upper.x, 0); ++x)
            for (int64_t y = cellOf(b.lower.y, 1); y <= cellOf(b.upper.y, 1); ++y)
                for (int64_t z = cellOf(b.lower.z, 2); z <= cellOf(b.upper.z, 2); ++z)
                    cells_[uint64_t(x & 0x1FFFFF) << 42 | uint64_t(y & 0x1FFFFF) << 21 | uint64_t(z & 0x1FFFFF)].push_back(t);
    }
}

uint64_t TriangleGrid::key(const Vec3d& p) const {
    auto cellOf = [&](double x, int axis) { return int64_t(std::floor((x - double(bounds_.lower[axis])) / cell_)); };
    return uint64_t(cellOf(p.x, 0) & 0x1FFFFF) << 42 | uint64_t(cellOf(p.y, 1) & 0x1FFFFF) << 21 | uint64_t(cellOf(p.z, 2) & 0x1FFFFF);
}

const std::vector<uint32_t>& TriangleGrid::near(const Vec3d& p) const {
    const auto it = cells_.find(key(p));
    return it == cells_.end() ? none_ : it->second;
}

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

std::vector<uint32_t> edgeConnectedPieces(const std::vector<Triangle>& triangles, const MeshTopology& topology) {
    std::vector<uint32_t> parent(triangles.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto root = [&](uint32_t t) {
        while (parent[t] != t) t = parent[t] = parent[parent[t]];
        return t;
    };
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> firstUser;
    for (uint32_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = topology.weldedId(triangles[t].v[k]), b = topology.weldedId(triangles[t].v[(k + 1) % 3]);
            if (a == b) continue;
            const auto [it, added] = firstUser.emplace(std::minmax(a, b), t);
            if (added) continue;
            // The smaller root stays: every piece is named by its smallest triangle.
            const uint32_t ra = root(it->second), rb = root(t);
            if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
        }
    std::vector<uint32_t> piece(triangles.size());
    for (uint32_t t = 0; t < triangles.size(); ++t) piece[t] = root(t);
    return piece;
}

}  // namespace qsgi
