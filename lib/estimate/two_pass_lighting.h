// The second pass over the photons' solution (docs/design.md §5.1, issue 33). Per vertex v with albedo
// ρ_v: D_v direct irradiance, exact (DirectLight); I_v the estimator's answer counting only light
// after its first bounce; F_u = ρ_u (D_u + I_u) the first pass; then
//   E_v = D_v + (M > 0 ? mean of F over v's gather rays (FinalGather) : I_v),  B_v = ρ_v E_v + π L_e,v,
// where the gather reads F at covered vertices (under a block standing on the floor) as their
// visible neighbours' (covered_vertices.h), except from the covered vertices themselves.
// It owns what that takes — the direct light and the gather's kept hits — and keeps each up to date
// across a move, touching only what the move can change, so that every update gives the bits a
// from-scratch solve of the same pose gives. The rays leave from the vertices themselves: their
// start points are VertexGeometry's (one owner for the solver's per-vertex geometry), handed in.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "estimate/direct_light.h"
#include "estimate/final_gather.h"
#include "estimate/gather_cache.h"
#include "estimate/lighting_settings.h"
#include "estimate/vertex_radiosity.h"
#include "estimate/vertex_starts.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/work_counter.h"

namespace qsgi {

// What a pose changed, as the second pass reads it. The scene and BVH already hold the new pose.
struct MovedGeometry {
    const std::vector<Bounds3f>& bounds;  // old and new bounds of each moved part
    const std::vector<uint8_t>& vertexMoved;
};

// What a solve or an update measured, for the frame's record.
struct SecondPassReport {
    double directSeconds = 0, gatherSeconds = 0;  // the gather's includes combining the passes
    uint64_t shadowRays = 0, gatherRays = 0;
    uint64_t gatherRecords = 0;  // with the gather cache: the vertices that gathered all M rays
};

class TwoPassLighting {
public:
    TwoPassLighting(const LightingSettings& settings, uint64_t seed);

    // What the gather keeps at most, for a run's pre-flight (issue 48): its hits (GatherHit, 16
    // bytes each), per vertex the cache's probes, or all M rays when frames will update from
    // this one; none when every frame streams them (a run of one frame, --full-recompute).
    // `settings` resolved for the scene (LightingSettings::resolvedFor).
    struct KeptHits {
        uint64_t perVertex = 0;
        uint64_t bytes = 0;  // saturating
    };
    static KeptHits keptGatherHits(const LightingSettings& settings, size_t vertices, bool updatesFollow);

    // From scratch for the current pose (bvh and starts hold it). photons: the estimator's
    // answer (after the first bounce). keepForUpdates false: no frame will update from this one
    // (the last frame, --full-recompute), so the gather keeps no hits — the same bits, without M
    // hits a vertex of memory — and the next frame solves from scratch.
    SecondPassReport solve(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const VertexRadiosity& photons,
                           VertexRadiosity& out, WorkCounter* progress = nullptr, bool keepForUpdates = true);
    // The last solve's or update's state brought to the current pose. newStarts: the vertices
    // whose start point or normal the pose changed (VertexStarts::update's answer).
    SecondPassReport update(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts,
                            const std::vector<uint32_t>& newStarts, const MovedGeometry& moved, const VertexRadiosity& photons,
                            VertexRadiosity& out);
    bool solved() const { return solved_; }
    void reset() { solved_ = false; }

    // Bytes kept across frames (direct light, gather hits, the cache's records and weights).
    size_t stateBytes() const;
    // The gather cache of the last solve or update (nullptr without one).
    const GatherCache* gatherCache() const { return cache_ ? &*cache_ : nullptr; }
    // Exact direct light (its light tree: DirectLight::sampledEmitters and the rest).
    const DirectLight& directLight() const { return direct_; }
    // The covered vertices of the last solve or update (FinalGather's rule; empty without a gather).
    const std::vector<uint8_t>& covered() const { return covered_; }

private:
    void combine(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const VertexRadiosity& photons,
                 VertexRadiosity& out);
    // What the gather reads of the first pass: F_u = ρ_u (D_u + I_u), 0 at hidden vertices, as
    // solved and with the covered vertices' (covered_) stand-ins (fillCoveredFirstPass), which
    // the rays of every other vertex read; where an albedo varies over a triangle, D + I alike.
    struct FirstPassValues {
        std::vector<Vec3f> solved, filled, solvedIrradiance, filledIrradiance;
        const SurfaceLookup* surfaces = nullptr;
        FinalGather::FirstPass view(const std::vector<uint8_t>& covered) const {
            return {filled, solved, covered, surfaces, &filledIrradiance, &solvedIrradiance};
        }
    };
    FirstPassValues firstPass(const Scene& scene, const SceneBvh& bvh, const VertexRadiosity& photons);
    // The gathered mean at the dark back sides (dark_) set to 0.
    void zeroDark(std::vector<Vec3f>& gathered) const;
    // E = D + the gathered mean, and B.
    void addDirect(const Scene& scene, VertexRadiosity& out) const;
    // With the cache: the records for the current pose, and the rest of their rays. Returns how
    // many records there are (0 without the cache).
    uint64_t placeRecords(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress = nullptr);

    LightingSettings settings_;
    DirectLight direct_;
    FinalGather gather_;
    std::optional<GatherCache> cache_;  // with --gather-cache A
    std::vector<uint8_t> covered_;
    std::vector<uint8_t> dark_;  // the dark back sides (FinalGather::darkBackSides); empty without back sides
    bool solved_ = false;
};

}  // namespace qsgi
