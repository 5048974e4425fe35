#include "estimate/mesh_bands.h"

#include <algorithm>
#include <cmath>
#include <map>

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

}  // namespace qsgi
