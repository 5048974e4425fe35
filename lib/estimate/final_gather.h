// The final gather (docs/design.md §5.1; Jensen's two-pass method with the first pass stored at the
// vertices): from each vertex's start point s_v (VertexStarts: v itself, a float error up), M cosine-distributed rays about n_v (v's own
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

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <vector>

#include "estimate/lighting_settings.h"
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
    // probeRays: with a gather cache (GatherCache), the rays every vertex casts (the first of its
    // M): the records cast the rest. 0, or M or more: every vertex casts all M (no cache).
    FinalGather(uint32_t raysPerVertex, uint64_t seed, uint32_t probeRays = 0)
        : rays_(raysPerVertex), probes_(probeRays == 0 ? raysPerVertex : std::min(probeRays, raysPerVertex)), seed_(seed) {}

    // Every vertex's first probeRays() rays, for the scene's current pose (bvh holds it); no
    // vertex is a record until setRecords (without a cache, every vertex has all its rays).
    // progress counts rays, of every vertex's M (with a cache, setRecords then says how many).
    void castAll(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress = nullptr);
    // Every kept ray of the given vertices (their start or normal changed).
    void cast(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint32_t>& vertices);
    // Re-casts the kept rays of the other vertices (skip[v] = 0) whose segment meets one of
    // `boxes`; returns how many.
    uint64_t recastMeeting(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                           const std::vector<Bounds3f>& boxes, const std::vector<uint8_t>& skip);
    // With a cache: the vertices with record[v] set cast the rest of their M rays (those that
    // already had them keep them), the others drop theirs.
    // progress: castAll's, in rays (its total, every vertex's M, is resized to what is cast).
    void setRecords(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint8_t>& record,
                    WorkCounter* progress = nullptr);

    // The first pass F as the rays read it (per vertex, the current pose's): `filled`, with the
    // covered vertices' stand-ins (fillCoveredFirstPass), for every vertex's rays but a covered
    // vertex's own, which read `solved`, F as it is. What lies a hair over a covered vertex (a
    // plate over a floor, a light panel under a ceiling: each covers the other) is covered too,
    // and its stand-in is the light outside the gap, not in it.
    // Where the albedo varies over a triangle (a texture, vertex colours: `surfaces`), a hit reads
    // the irradiance D + I interpolated over it times the albedo at the hit, not F interpolated
    // (which would average the texture between the vertices): `filledIrradiance` and
    // `solvedIrradiance` then hold D + I as `filled` and `solved` hold F.
    struct FirstPass {
        const std::vector<Vec3f>& filled;
        const std::vector<Vec3f>& solved;
        const std::vector<uint8_t>& covered;  // empty: every vertex reads `filled`
        const SurfaceLookup* surfaces = nullptr;  // null or none varies: F everywhere
        const std::vector<Vec3f>* filledIrradiance = nullptr;
        const std::vector<Vec3f>* solvedIrradiance = nullptr;
        bool coveredVertex(uint32_t v) const { return v < covered.size() && covered[v]; }
        const std::vector<Vec3f>& readBy(uint32_t v) const { return coveredVertex(v) ? solved : filled; }
        const std::vector<Vec3f>* irradianceReadBy(uint32_t v) const {
            if (!surfaces || !surfaces->any()) return nullptr;
            return coveredVertex(v) ? solvedIrradiance : filledIrradiance;
        }
    };
    // Each vertex's gathered irradiance from the first pass; 0 at a vertex that does not have all
    // M rays (a cache interpolates those).
    void gather(const Scene& scene, const FirstPass& firstPass, std::vector<Vec3f>& out) const;
    // The same, every vertex's rays reading `firstPass`.
    void gather(const Scene& scene, const std::vector<Vec3f>& firstPass, std::vector<Vec3f>& out) const;
    // castAll and gather at once, keeping no hit: each vertex's hits are cast into a buffer of M
    // and summed at once, in ray order — the same bits as castAll then gather — when no frame will
    // update from this one (the last frame, --full-recompute), so that a frame needs no M hits a
    // vertex of memory. Leaves nothing to update: hit() and the re-casts need a castAll first.
    // Without a cache only.
    void castAndGather(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const FirstPass& firstPass,
                       std::vector<Vec3f>& out, WorkCounter* progress = nullptr);
    // Drops every kept hit.
    void clear();

    // Covered vertices (docs/design.md §5.1, issues 47 and 56): every one of v's first coverRays()
    // gather rays is blocked — by a back face (its start lies inside closed geometry: the floor
    // under a block standing on it), or by a front face lower above v's tangent plane than
    // starts.coverHeight(v), a quarter of v's longest edge (a part lying a hair over v: a strap
    // on a shell, a plate on a floor, whichever mesh it belongs to). Not a vertex under a table
    // top: its grazing rays escape or meet surfaces higher than that. Read from the kept hits
    // (every vertex keeps its probes, which hold those rays) or, for castAndGather, which keeps
    // none, cast afresh: the same rays, the same answer.
    static constexpr uint32_t kCoverRays = 16;
    uint32_t coverRays() const { return std::min({rays_, probes_, kCoverRays}); }
    std::vector<uint8_t> coveredFromKept(const Scene& scene, const VertexStarts& starts) const;
    std::vector<uint8_t> castCovered(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts) const;
    // The dark back sides (lib/scene/back_sides.h): back vertices that are covered — the inside of
    // a closed or tube-like doubleSided mesh, whose cover rays meet its back faces. They are 0:
    // a dark one casts its cover rays alone (its other rays are kept as misses, and a re-cast
    // that reaches it casts it whole), and direct light skips it. From the kept probes, or, given
    // `covered` (castCovered's, for castAndGather), from that.
    std::vector<uint8_t> darkBackSides(const Scene& scene, const VertexStarts& starts,
                                       const std::vector<uint8_t>& covered = {}) const;

    uint32_t raysPerVertex() const { return rays_; }
    uint32_t probeRays() const { return probes_; }
    bool cached() const { return probes_ < rays_; }
    // The direction a kept hit's ray was cast along (decoded from its 16-bit octahedral form).
    static Vec3f rayDirection(const GatherHit& hit);
    // Ray `ray` of v: one of its probes, or (a record's) one of the rest.
    const GatherHit& hit(uint32_t v, uint32_t ray) const {
        assert(size_t(v) * probes_ < probeHits_.size() && (ray < probes_ || restSlot_[v] != kNoSlot));
        return ray < probes_ ? probeHits_[size_t(v) * probes_ + ray] : restOf(v)[ray - probes_];
    }
    bool hasAllRays(uint32_t v) const { return !cached() || restSlot_[v] != kNoSlot; }
    // Rays cast by the last castAll(), or by cast(), recastMeeting() and setRecords() since then.
    uint64_t raysCast() const { return raysCast_; }
    void resetRayCount() { raysCast_ = 0; }
    size_t bytes() const {
        return (probeHits_.capacity() + restHits_.capacity()) * sizeof(GatherHit) + restSlot_.capacity() * sizeof(uint32_t);
    }

private:
    class Directions;
    static constexpr uint32_t kNoSlot = UINT32_MAX;
    // The mean over a vertex's M hits (first its probes, then the rest, in ray order) of F
    // interpolated at each (gather's sum, castAndGather's).
    Vec3f meanOverHits(const Scene& scene, const FirstPass& firstPass, uint32_t v, const GatherHit* probes,
                       const GatherHit* rest) const;
    GatherHit castRay(const SceneBvh& bvh, const std::vector<Vec3f>& frontNormals, const Vec3f& origin,
                      const Vec3f& direction) const;
    // Rays [first, first + count) of v along its Sobol directions, into `hits`: each direction
    // stored in 16-bit octahedral form and the ray cast along that decoded direction (a hidden
    // vertex: misses).
    void castVertexInto(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                        const std::vector<Vec3f>& frontNormals, uint32_t v, uint32_t first, uint32_t count,
                        GatherHit* hits) const;
    // Every kept ray of v.
    bool darkBackSide(const Scene& scene, const VertexStarts& starts, uint32_t v, const GatherHit* cover) const;
    void castVertex(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                    const std::vector<Vec3f>& frontNormals, uint32_t v);
    // A record's hits after its probes.
    GatherHit* restOf(uint32_t v) { return &restHits_[size_t(restSlot_[v]) * (rays_ - probes_)]; }
    const GatherHit* restOf(uint32_t v) const { return &restHits_[size_t(restSlot_[v]) * (rays_ - probes_)]; }

    uint32_t rays_, probes_;
    uint64_t seed_;
    std::vector<GatherHit> probeHits_;  // vertex-major, probes_ a vertex
    // The records' other rays_ - probes_ hits, in slots; restSlot_[v] is v's slot or kNoSlot.
    std::vector<GatherHit> restHits_;
    std::vector<uint32_t> restSlot_, freeSlots_;
    uint64_t raysCast_ = 0;
    static_assert(kCoverRays <= LightingSettings::kGatherProbeRays, "every vertex keeps the rays that decide its cover");
};

}  // namespace qsgi
