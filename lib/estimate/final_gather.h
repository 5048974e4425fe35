// The final gather (docs/design.md §5.1; Jensen's two-pass method with the first pass stored at the
// vertices): from each vertex's start point s_v, M cosine-distributed rays about n_v (v's own
// scrambled Sobol points), each returning the first pass F interpolated over the triangle it hits
// — F_u = ρ_u (D_u + I_u), the light a vertex reflects, emission excluded (exact direct light
// already holds what comes straight from the emitters). A ray that escapes returns 0, and so does
// one that meets a triangle's back face: vertex radiosity is the front side's, and a back face
// seen from v is the inside of a closed object or a single-sided sheet whose back no estimator
// lights. The gathered irradiance is the rays' mean (cosine weighting cancels π).
//
// Each ray's hit is kept (triangle, distance, barycentrics quantised to 16 bits once, at the
// cast, and the ray's direction), 16 bytes: the mean is recomputed from kept hits whenever F changes, and a frame re-casts
// only the rays whose segment (s_v to the hit, or to infinity for a miss) meets a mover's old or
// new bounds, and every ray of a vertex whose start or normal changed. A kept ray met neither
// position of anything that moved, so its hit is the one a re-cast would find; the means are
// summed per vertex in ray order, so updates and full recomputations agree to the bit.
#pragma once

#include <cstdint>
#include <vector>

#include "estimate/vertex_starts.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/work_counter.h"

namespace qsgi {

struct GatherHit {
    static constexpr uint32_t kMiss = 0xFFFFFFFFu, kBackFace = 0xFFFFFFFEu;
    uint32_t triangle = kMiss;  // scene triangle, or kMiss / kBackFace (both return 0)
    float t = 0;                // distance to the hit (infinite for a miss): the ray's segment
    uint16_t b1 = 0, b2 = 0;    // barycentrics of the triangle's vertices 1 and 2, in 1/65535
    // The ray's direction, octahedral, 16 bits a coordinate: the ray is cast along exactly this
    // (decoded) direction, so that a frame's scan for rays meeting a mover reads it instead of
    // drawing the vertex's Sobol point again (a quarter of an incremental frame on data/cornell).
    uint16_t octU = 0, octV = 0;
};
static_assert(sizeof(GatherHit) == 16, "the kept hit's size, as the docs state it");

class FinalGather {
public:
    FinalGather(uint32_t raysPerVertex, uint64_t seed) : rays_(raysPerVertex), seed_(seed) {}

    // Every vertex's rays, for the scene's current pose (bvh holds it).
    void castAll(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress = nullptr);
    // Every ray of the given vertices (their start or normal changed).
    void cast(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint32_t>& vertices);
    // Re-casts the rays of the other vertices (skip[v] = 0) whose segment meets one of `boxes`;
    // returns how many.
    uint64_t recastMeeting(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                           const std::vector<Bounds3f>& boxes, const std::vector<uint8_t>& skip);

    // Each vertex's gathered irradiance from the first pass F (per vertex, the current pose's).
    void gather(const Scene& scene, const std::vector<Vec3f>& firstPass, std::vector<Vec3f>& out) const;
    // castAll and gather at once, keeping no hit: each vertex's hits are cast into a buffer of M
    // and summed at once, in ray order — the same bits as castAll then gather — when no frame will
    // update from this one (the last frame, --full-recompute), so that a frame needs no M hits a
    // vertex of memory. Leaves nothing to update: hit() and the re-casts need a castAll first.
    void castAndGather(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                       const std::vector<Vec3f>& firstPass, std::vector<Vec3f>& out, WorkCounter* progress = nullptr);

    uint32_t raysPerVertex() const { return rays_; }
    // The direction a kept hit's ray was cast along (decoded from its 16-bit octahedral form).
    static Vec3f rayDirection(const GatherHit& hit);
    const GatherHit& hit(uint32_t v, uint32_t ray) const { return hits_[size_t(v) * rays_ + ray]; }
    // Rays cast by the last castAll(), or by cast() and recastMeeting() since the last castAll().
    uint64_t raysCast() const { return raysCast_; }
    void resetRayCount() { raysCast_ = 0; }
    size_t bytes() const { return hits_.capacity() * sizeof(GatherHit); }

private:
    class Directions;
    // The mean over a vertex's M hits of F interpolated at each (gather's sum, castAndGather's).
    Vec3f meanOverHits(const Scene& scene, const std::vector<Vec3f>& firstPass, const GatherHit* hits) const;
    GatherHit castRay(const SceneBvh& bvh, const std::vector<Vec3f>& frontNormals, const Vec3f& origin,
                      const Vec3f& direction) const;
    void castVertex(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                    const std::vector<Vec3f>& frontNormals, uint32_t v);
    // A vertex's M rays along its Sobol directions, into `hits`: each direction stored in 16-bit
    // octahedral form and the ray cast along that decoded direction (a hidden vertex: misses).
    void castVertexInto(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                        const std::vector<Vec3f>& frontNormals, uint32_t v, GatherHit* hits) const;

    uint32_t rays_;
    uint64_t seed_;
    std::vector<GatherHit> hits_;  // vertex-major
    uint64_t raysCast_ = 0;
};

}  // namespace qsgi
