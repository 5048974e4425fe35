// Density estimation on the tangent plane (DESIGN §5, Lastra et al. 2002). Vertex v owns the disc
// D_v = { p : (p − v)·n_v = 0, |p − v| ≤ r }. Segment s counts when d·n_v < 0 and its line
// crosses the disc's plane at 0 < t* ≤ t_s + r with |o + t* d − v| ≤ r: the segment is extended
// by one radius past its impact, so a disc reaching behind an adjacent wall still sees the flux
// arriving there. E_v = Σ Φ_s / (π r²).
//
// The exact ray–disc test (segmentCrossesDisc) is the definition. The Embree index traces each
// segment through oriented discs at the vertices — slightly enlarged, so it finds a superset —
// and keeps exactly the discs the test accepts; brute force applies the same test to every pair.
// Both therefore count the same set, and fixed-point sums make them equal to the last bit.
#pragma once

#include <vector>

#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/ray_cache.h"

namespace qsgi {

bool segmentCrossesDisc(const Segment& s, const Vec3f& centre, const Vec3f& normal, float radius);

struct DetpQueryStats {
    uint64_t discHits = 0;  // accepted (segment, disc) pairs
};

class DetpDiscs {
public:
    // Builds the disc BVH of the scene's current pose.
    DetpDiscs(const EmbreeDevice& device, const Scene& scene, float radius);

    // Irradiance at every vertex from the given segments (in that order), in parallel.
    std::vector<Vec3f> irradiance(const RayCache& cache, const std::vector<uint32_t>& segmentOrder,
                                  DetpQueryStats* stats = nullptr) const;

private:
    const Scene& scene_;
    float radius_;
    float rayExtension_;  // lets Embree's float tests see crossings at t* ≈ 0 and t* ≈ t + r
    EmbreeScene discs_;
};

// Index-free reference: every segment against every disc.
std::vector<Vec3f> detpBruteForce(const Scene& scene, const RayCache& cache, float radius);

// Approximate DETP (--detp-index flann): candidates are the segments whose impact lies within
// radius·(1 + kFlannCandidateMargin) of the vertex, then the exact test. It misses segments that
// cross a disc but land far away (silhouettes, convex edges, escaping photons).
constexpr float kFlannCandidateMargin = 0.25f;
std::vector<Vec3f> detpFlannCandidates(const Scene& scene, const RayCache& cache, float radius,
                                       const std::vector<uint32_t>& vertexOrder);

// Segment order for coherent tracing: Morton order of the segments' end points.
std::vector<uint32_t> segmentMortonOrder(const RayCache& cache);

}  // namespace qsgi
