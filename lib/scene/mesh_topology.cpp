#include "scene/mesh_topology.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <numeric>
#include <tuple>

#include "scene/scene.h"

namespace qsgi {

namespace {
// Bit pattern of a coordinate, with -0 and +0 made equal (they are the same position).
uint32_t positionBits(float x) {
    x += 0.0f;
    uint32_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    return bits;
}
}  // namespace

MeshTopology::MeshTopology(const Scene& scene)
    : MeshTopology(scene.positions, scene.triangles, uint32_t(scene.frontVertexCount())) {}

MeshTopology::MeshTopology(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, uint32_t sideFrom) {
    const size_t n = positions.size();
    // Sort vertex indices by position (then index): each run of equal positions is one weld.
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    auto place = [&](uint32_t v) {
        return std::make_tuple(v >= sideFrom, positionBits(positions[v].x), positionBits(positions[v].y),
                               positionBits(positions[v].z));
    };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return std::make_tuple(place(a), a) < std::make_tuple(place(b), b);
    });
    welded_.resize(n);
    for (size_t i = 0; i < n;) {
        size_t j = i;
        while (j < n && place(order[j]) == place(order[i])) ++j;
        for (size_t k = i; k < j; ++k) welded_[order[k]] = order[i];  // order[i] is the run's smallest index
        i = j;
    }
    // Incident triangles per welded id (counting sort keeps triangle order increasing). A
    // triangle with two corners at one place is listed once there.
    auto forEachDistinctCorner = [&](const Triangle& t, auto&& visit) {
        const uint32_t a = welded_[t.v[0]], b = welded_[t.v[1]], c = welded_[t.v[2]];
        visit(a);
        if (b != a) visit(b);
        if (c != a && c != b) visit(c);
    };
    first_.assign(n + 1, 0);
    for (const Triangle& t : triangles) forEachDistinctCorner(t, [&](uint32_t w) { ++first_[w + 1]; });
    for (size_t i = 0; i < n; ++i) first_[i + 1] += first_[i];
    incident_.resize(first_[n]);
    std::vector<uint32_t> fill(first_.begin(), first_.end() - 1);
    for (uint32_t t = 0; t < triangles.size(); ++t)
        forEachDistinctCorner(triangles[t], [&](uint32_t w) { incident_[fill[w]++] = t; });
}

std::vector<uint32_t> MeshTopology::vertexPieces(const std::vector<Triangle>& triangles) const {
    // Union–find over welded ids, each triangle joining its three corners; the smaller root wins.
    std::vector<uint32_t> parent(welded_);
    auto root = [&](uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (const Triangle& T : triangles)
        for (int k = 1; k < 3; ++k) {
            const uint32_t a = root(T.v[0]), b = root(T.v[k]);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    std::vector<uint32_t> pieces(parent.size());
    for (uint32_t v = 0; v < pieces.size(); ++v) pieces[v] = root(v);
    return pieces;
}

std::vector<uint32_t> MeshTopology::edgeConnectedPieces(const std::vector<Triangle>& triangles) const {
    std::vector<uint32_t> parent(triangles.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto root = [&](uint32_t t) {
        while (parent[t] != t) t = parent[t] = parent[parent[t]];
        return t;
    };
    // Every edge (welded) with the triangles that use it; (0, 0) until a first, then a second.
    std::map<std::pair<uint32_t, uint32_t>, std::pair<uint32_t, uint32_t>> users;
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> useCount;
    for (uint32_t t = 0; t < triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = weldedId(triangles[t].v[k]), b = weldedId(triangles[t].v[(k + 1) % 3]);
            if (a == b) continue;
            const auto edge = std::minmax(a, b);
            const uint32_t n = ++useCount[edge];
            if (n == 1) users[edge].first = t;
            else if (n == 2) users[edge].second = t;
        }
    // Joined across edges that exactly two triangles use: an edge with a third is where one
    // surface stands on another (a block's foot along a row of floor edges), not where one turns.
    for (const auto& [edge, count] : useCount) {
        if (count != 2) continue;
        const auto& [t0, t1] = users[edge];
        // The smaller root stays: every piece is named by its smallest triangle.
        const uint32_t ra = root(t0), rb = root(t1);
        if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
    }
    std::vector<uint32_t> piece(triangles.size());
    for (uint32_t t = 0; t < triangles.size(); ++t) piece[t] = root(t);
    return piece;
}

}  // namespace qsgi
