// Photon map (DESIGN §5): the k nearest impacts h_s to vertex v that count for v, searched within
// `radius`; r_k is the distance to the k-th. An impact counts when it arrives from the front
// (d_s·n_v < 0) and — with disc regions — lies on a surface facing n_v (front face normal within
// 45°) between ε_v⁻ below and ε_v⁺ above v's tangent plane, so a panel under a ceiling or a plate
// over a floor lends the surface beneath none of its photons. E_v = Σ Φ_s over the k−1 impacts
// strictly inside r_k, divided by the area of the r_k disc that such surfaces cover (DiscRegions'
// covered cells; π r_k² where all are covered). DESIGN sums all k, which overestimates by
// k/(k−1); see estimate(). With fewer than k inside `radius`, all of them over the covered part
// of the radius disc. Without regions (the `paper` ablation, and vertices whose own surface is
// empty) the textbook rule: front-facing impacts over π r_k².
// The ImpactIndex kd-tree answers the queries; bruteForce() is the index-free reference that
// must give the same answers.
#pragma once

#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/fixed_point_power.h"
#include "estimate/impact_index.h"
#include "scene/scene.h"

namespace qsgi {

class PhotonMap {
public:
    // Builds the kd-tree once per photon set; keeps a reference to the cache.
    // bvh: the scene's triangles in the current pose, to decide impacts in mixed cells.
    PhotonMap(const RayCache& cache, const Scene& scene, const SceneBvh* bvh);

    // Irradiance at every vertex, queries in `order` (a permutation of the vertices), in parallel.
    // regions: with coverage, for the scene's current pose; null for the textbook rule.
    std::vector<Vec3f> irradiance(const Scene& scene, const DiscRegions* regions, float radius, int k,
                                  const std::vector<uint32_t>& order) const;
    // The same answers without an index: every vertex against every impact.
    std::vector<Vec3f> bruteForce(const Scene& scene, const DiscRegions* regions, float radius, int k) const;

private:
    // Equal distances are ordered by (path, bounce): the k nearest are the same set whatever
    // order the cache holds the impacts in (an incremental update reorders it).
    struct Neighbour {
        float distanceSquared;
        uint64_t pathBounce;
        uint32_t impact;
        bool operator<(const Neighbour& o) const {
            return distanceSquared < o.distanceSquared || (distanceSquared == o.distanceSquared && pathBounce < o.pathBounce);
        }
    };
    Neighbour neighbour(float distanceSquared, uint32_t impact) const {
        const Segment& s = segmentOf(impact);
        return {distanceSquared, uint64_t(s.path) << 16 | s.bounce, impact};
    }
    // Whether impact i counts for vertex v (front side, and v's own band with regions).
    struct VertexFilter {
        Vec3d position, normal;
        const VertexDisc* disc;  // null: front side only
        float radius;            // the regions' disc radius
    };
    VertexFilter filterFor(const Scene& scene, const DiscRegions* regions, size_t v) const;
    bool counts(const VertexFilter& f, uint32_t impact) const;
    // E from the counted neighbours, nearest first.
    Vec3f estimate(const std::vector<Neighbour>& sortedCounted, const VertexDisc* disc, float radius, int k) const;
    const Segment& segmentOf(uint32_t impact) const { return cache_.segments[index_.segment(impact)]; }

    const RayCache& cache_;
    ImpactIndex index_;
    std::vector<Vec3f> frontNormals_;
    const SceneBvh* bvh_;  // of the impacted triangles, for the 45° test
    PowerQuantizer quantizer_;
};

}  // namespace qsgi
