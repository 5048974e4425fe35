#include "estimate/covered_vertices.h"

#include <algorithm>

#include "estimate/own_surface.h"
#include "scene/mesh_topology.h"

namespace qsgi {

void fillCoveredFirstPass(const Scene& scene, const std::vector<uint8_t>& covered, std::vector<Vec3f>& firstPass) {
    const size_t n = scene.vertexCount();
    if (std::find(covered.begin(), covered.end(), uint8_t(1)) == covered.end()) return;
    const MeshTopology topology(scene);
    // known[v]: v's value is final — visible, or a covered vertex filled in an earlier ring.
    std::vector<uint8_t> known(n);
    for (size_t v = 0; v < n; ++v) known[v] = !covered[v] && !scene.vertexHidden[v];
    auto forEachNeighbour = [&](uint32_t v, auto&& visit) {
        for (const uint32_t* it = topology.trianglesBegin(v); it != topology.trianglesEnd(v); ++it)
            for (uint32_t u : scene.triangles[*it].v)
                if (topology.weldedId(u) != topology.weldedId(v) && dot(scene.normals[u], scene.normals[v]) > kOwnSurfaceCos)
                    visit(u);
    };
    // Ring by ring: a ring's covered vertices take the mean of their neighbours known before it
    // (the order within a ring changes nothing); the next ring is every covered vertex not yet
    // known that neighbours one filled now, with those of this ring that had no known neighbour
    // (a split twin reached through its twin's triangles) asked again. It ends when a ring fills
    // none.
    std::vector<uint32_t> ring;
    for (uint32_t v = 0; v < n; ++v) {
        if (!covered[v] || known[v]) continue;
        bool nearKnown = false;
        forEachNeighbour(v, [&](uint32_t u) { nearKnown = nearKnown || known[u]; });
        if (nearKnown) ring.push_back(v);
    }
    std::vector<uint8_t> queued(n, 0);
    std::vector<Vec3f> values;
    std::vector<uint8_t> filled;
    while (!ring.empty()) {
        values.assign(ring.size(), Vec3f(0.0f));
        filled.assign(ring.size(), 0);
        for (size_t i = 0; i < ring.size(); ++i) {
            Vec3d sum(0.0);
            uint32_t count = 0;
            forEachNeighbour(ring[i], [&](uint32_t u) {
                if (!known[u]) return;
                sum += Vec3d(firstPass[u]);
                ++count;
            });
            if (count == 0) continue;
            values[i] = Vec3f(sum / double(count));
            filled[i] = 1;
        }
        bool any = false;
        for (size_t i = 0; i < ring.size(); ++i) {
            if (!filled[i]) continue;
            firstPass[ring[i]] = values[i];
            known[ring[i]] = 1;
            any = true;
        }
        if (!any) break;
        std::vector<uint32_t> next;
        for (size_t i = 0; i < ring.size(); ++i) {
            if (!filled[i]) {
                if (!queued[ring[i]]) queued[ring[i]] = 1, next.push_back(ring[i]);
                continue;
            }
            forEachNeighbour(ring[i], [&](uint32_t u) {
                if (covered[u] && !known[u] && !queued[u]) {
                    queued[u] = 1;
                    next.push_back(u);
                }
            });
        }
        for (uint32_t u : next) queued[u] = 0;  // it only keeps a ring free of repeats
        ring = std::move(next);
    }
}

}  // namespace qsgi
