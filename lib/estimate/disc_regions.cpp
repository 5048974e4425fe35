#include "estimate/disc_regions.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "estimate/own_surface.h"
#include "scene/mesh_topology.h"

namespace qsgi {

bool VertexDisc::operator==(const VertexDisc& o) const {
    return tangent == o.tangent && bitangent == o.bitangent && epsAbove == o.epsAbove && epsBelow == o.epsBelow &&
           reachable == o.reachable && covered == o.covered && reachableCells == o.reachableCells &&
           coveredCells == o.coveredCells && fallback == o.fallback;
}

namespace {

VertexDisc computeVertexDisc(uint32_t v, const Scene& scene, const SceneBvh& bvh, const MeshTopology& topology,
                             const std::vector<Vec3f>& frontNormals, float radius, bool withCoverage,
                             OwnSurfaceScratch& scratch) {
    VertexDisc disc;
    const Vec3f& normal = scene.normals[v];
    discFrame(normal, disc.tangent, disc.bitangent);
    const OwnSurface own = findOwnSurface(v, scene, topology, frontNormals, radius, scratch);
    if (own.empty) {
        disc.fallback = true;
        return disc;
    }
    disc.epsAbove = own.epsAbove;
    disc.epsBelow = own.epsBelow;
    // Double precision for the points, so the float rays start exactly where the rule says.
    const Vec3d p(scene.positions[v]), n(normal), t(disc.tangent), b(disc.bitangent);
    const double r = radius, lift = own.epsAbove;
    const double sideStep = std::min(1e-3 * r, double(scene.sceneEpsilon()));
    const Vec3d start = p + n * lift + Vec3d(own.towardSurface) * sideStep;
    for (int c = 0; c < kDiscCells; ++c) {
        double x, y;
        discCellCentre(c, x, y);
        const Vec3d centre = p + (t * x + b * y) * r + n * lift;
        const Vec3d d = centre - start;
        const double len = length(d);
        if (len > 0 && bvh.occluded(Vec3f(start), Vec3f(d / len), 0.0f, float(len))) continue;
        disc.reachable.set(c);
        if (!withCoverage) continue;
        // Probe straight down through the band [−ε⁻, ε⁺] for a surface facing n_v.
        const auto hit = bvh.intersect(Vec3f(centre), -normal, 0.0f, own.epsAbove + own.epsBelow);
        if (hit && dot(frontNormals[hit->triangle], normal) > kOwnSurfaceCos) disc.covered.set(c);
    }
    disc.reachableCells = uint16_t(disc.reachable.count());
    disc.coveredCells = uint16_t(disc.covered.count());
    return disc;
}

}  // namespace

void DiscRegions::computeAll(const Scene& scene, const SceneBvh& bvh) {
    discs_.assign(scene.vertexCount(), VertexDisc{});
    std::vector<uint32_t> all(scene.vertexCount());
    for (uint32_t v = 0; v < all.size(); ++v) all[v] = v;
    recompute(scene, bvh, all);
}

void DiscRegions::recompute(const Scene& scene, const SceneBvh& bvh, const std::vector<uint32_t>& vertices) {
    if (discs_.size() != scene.vertexCount()) discs_.resize(scene.vertexCount());
    if (vertices.empty()) return;
    const MeshTopology topology(scene.positions, scene.triangles);
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    // Each vertex depends on nothing but the geometry: any schedule gives the same bytes.
    tbb::enumerable_thread_specific<OwnSurfaceScratch> scratch;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 32), [&](const tbb::blocked_range<size_t>& range) {
        OwnSurfaceScratch& local = scratch.local();
        for (size_t i = range.begin(); i != range.end(); ++i)
            discs_[vertices[i]] =
                computeVertexDisc(vertices[i], scene, bvh, topology, frontNormals, radius_, withCoverage_, local);
    });
}

std::vector<uint32_t> DiscRegions::touchedBy(const Scene& scene, const std::vector<Bounds3f>& movedBounds,
                                             const std::vector<uint8_t>& vertexMoved) const {
    // The test region (cylinder of radius r, |h| ≤ r; the reachability segments and probes stay
    // inside it) lies within r·√2 of v; the scene epsilon covers the lift of the start point.
    const float reach = radius_ * 1.41421357f + 4 * scene.sceneEpsilon();
    std::vector<uint32_t> touched;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        bool hit = v < vertexMoved.size() && vertexMoved[v];
        if (!hit) {
            Bounds3f region;
            region.extend(scene.positions[v]);
            region = region.expanded(reach);
            for (const Bounds3f& b : movedBounds) hit = hit || region.overlaps(b);
        }
        if (hit) touched.push_back(v);
    }
    return touched;
}

uint64_t DiscRegions::fallbackVertices() const {
    return uint64_t(std::count_if(discs_.begin(), discs_.end(), [](const VertexDisc& d) { return d.fallback; }));
}

uint64_t DiscRegions::buriedVertices() const {
    return uint64_t(std::count_if(discs_.begin(), discs_.end(), [](const VertexDisc& d) { return !d.fallback && d.reachableCells == 0; }));
}

}  // namespace qsgi
