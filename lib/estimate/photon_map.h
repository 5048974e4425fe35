// Photon map (DESIGN §5): the k nearest impacts h_s to vertex v that arrive from the front
// (d_s · n_v < 0), searched within `radius`; r_k is the distance to the k-th. E_v = Σ Φ_s / (π r_k²)
// over the k−1 impacts strictly inside r_k (DESIGN sums all k, which overestimates by k/(k−1);
// see estimate()), or over all impacts within `radius` / (π radius²) if fewer than k were found. The ImpactIndex kd-tree answers the queries;
// bruteForce() is the index-free reference that must give the same answers.
#pragma once

#include <vector>

#include "estimate/fixed_point_power.h"
#include "estimate/impact_index.h"
#include "scene/scene.h"

namespace qsgi {

class PhotonMap {
public:
    // Builds the kd-tree once per photon set; keeps a reference to the cache.
    explicit PhotonMap(const RayCache& cache);

    // Irradiance at every vertex, queries in `order` (a permutation of the vertices), in parallel.
    std::vector<Vec3f> irradiance(const Scene& scene, float radius, int k, const std::vector<uint32_t>& order) const;
    // The same answers without an index: every vertex against every impact.
    std::vector<Vec3f> bruteForce(const Scene& scene, float radius, int k) const;

private:
    struct Neighbour {
        float distanceSquared;
        uint32_t impact;
        bool operator<(const Neighbour& o) const {
            return distanceSquared < o.distanceSquared || (distanceSquared == o.distanceSquared && impact < o.impact);
        }
    };
    // E from the front-facing neighbours, nearest first.
    Vec3f estimate(const std::vector<Neighbour>& sortedFront, float radius, int k) const;
    const Segment& segmentOf(uint32_t impact) const { return cache_.segments[index_.segment(impact)]; }

    const RayCache& cache_;
    ImpactIndex index_;
    PowerQuantizer quantizer_;
};

}  // namespace qsgi
