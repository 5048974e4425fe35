// Density estimation (docs/design.md §5–§6): one interface for the three estimators. Each solves a
// frame from scratch (every vertex from every segment) and updates the previous frame's answer
// from what a move changed (the segments retraced, the vertices and triangles moved). The
// caller — FrameSolver, tests, benchmarks — never switches on the kind. One file per estimator:
// impact_count_estimator.cpp, photon_map_estimator.cpp, detp_estimator.cpp.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "estimate/detp.h"
#include "estimate/disc_regions.h"
#include "estimate/estimator_settings.h"
#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/ray_cache.h"
#include "trace/scene_bvh.h"
#include "trace/tracked_paths.h"

namespace qsgi {

// Whether the estimator needs disc regions, and whether with the photon map's coverage.
bool needsDiscRegions(const EstimatorSettings& settings);
// The moved ones among `vertices` (in their order): what an estimator that reads no disc regions
// recomputes.
std::vector<uint32_t> movedOnly(const std::vector<uint32_t>& vertices, const std::vector<uint8_t>& vertexMoved);
DiscRegions makeDiscRegions(const EstimatorSettings& settings);

// What one frame changed, as an update reads it (docs/design.md §6 steps 2–4). The scene, its BVH and
// the disc regions already hold the new pose.
struct FrameChange {
    const std::vector<Segment>& removed;        // old tails, as they were cached before the move
    const std::vector<Segment>& added;          // new tails
    const std::vector<uint8_t>& vertexMoved;    // per scene vertex
    const std::vector<uint8_t>& triangleMoved;  // per scene triangle
    const std::vector<uint32_t>& movedTriangles;  // the same, listed (increasing)
    // Vertices whose disc moved or whose disc regions the move touched (sorted): they are
    // recomputed, every other vertex is updated.
    const std::vector<uint32_t>& touched;
    const TrackedPaths& tracked;  // every tracked segment after the change
};

// What a solve or an update measured, for the frame's record (FrameSolver assembles it).
struct EstimateReport {
    uint64_t verticesUpdated = 0;       // estimated again
    uint64_t verticesRecomputed = 0;    // an update's: from the segments near them, afresh
    uint64_t recomputeCandidates = 0;   // segments gathered for those recomputations
    uint64_t detpCrossings = 0;         // DETP from scratch: the (segment, disc) crossings counted
    uint64_t crossingsForgotten = 0;    // DETP update: removed crossings subtracted as remembered
    double updateSeconds = 0;           // an update's + new − old at the vertices that keep sums
    double recomputeSeconds = 0;        // an update's recomputed vertices
};

// Everything an estimator reads besides the segments; the references outlive it.
struct EstimatorContext {
    const Scene& scene;
    const SceneBvh& bvh;  // the scene's triangles in the current pose
    const EmbreeDevice& device;
    const DiscRegions* regions;  // null when the estimator needs none (needsDiscRegions)
    // Frames will be updated from this one (not --full-recompute): an estimator may keep what
    // its updates need while it solves (the photon map's neighbour lists).
    bool updatesFollow = false;
    // Counts a solve's work for a progress display (null: none); the solver names the stage.
    WorkCounter* progress = nullptr;
    // Exact direct light (--direct exact, docs/design.md §5.1): direct light is computed apart, so
    // the estimate holds only what arrives after at least one bounce — segments of bounce 0
    // (emission segments, and with them first impacts) count nowhere.
    bool afterFirstBounce = false;
};

class Estimator {
public:
    static std::unique_ptr<Estimator> create(const EstimatorSettings& settings, const EstimatorContext& context);
    virtual ~Estimator() = default;

    // Every vertex's irradiance and radiosity from every segment of the cache (current pose).
    virtual EstimateReport solve(const RayCache& cache, VertexRadiosity& out) = 0;

    // Incremental updates. Whether this estimator has one (otherwise every frame is solved from
    // scratch, and timing.json says "estimator").
    virtual bool canUpdate() const { return true; }
    // Of the vertices a pose change left different (moved, or their disc regions may now decide
    // differently: VertexGeometry::update; sorted), those this estimator recomputes from scratch;
    // every other vertex is updated from the segments that changed. All of them by default; an
    // estimator that reads no disc regions recomputes the moved ones only.
    virtual std::vector<uint32_t> verticesToRecompute(const std::vector<uint32_t>& changed,
                                                      const std::vector<uint8_t>& /*vertexMoved*/) const {
        return changed;
    }
    // How far past its impact a segment counts (DETP: r; the others count impacts only): the
    // envelope's margin and the tracked-segment grid follow from it. Paths that never meet the
    // envelope stay folded into the state solve() left.
    virtual float reach() const = 0;
    // Called after solve() and the tracked paths are known, before the first update.
    virtual void prepareUpdates(const TrackedPaths& tracked) = 0;
    // The previous frame's answer in `out` becomes this frame's.
    virtual EstimateReport update(const FrameChange& change, VertexRadiosity& out) = 0;
    // Frames will no longer be updated from this state (a frame solved from scratch, a reset):
    // what prepareUpdates() built goes, so no update state outlives the tracked paths it mirrors.
    virtual void dropUpdateState() {}
    // Bytes of incremental state (remembered crossings, indexes), apart from the tracked paths.
    virtual size_t stateBytes() const { return 0; }
};

// The estimators, for Estimator::create.
std::unique_ptr<Estimator> makeImpactCountEstimator(const EstimatorSettings& settings, const EstimatorContext& context);
std::unique_ptr<Estimator> makePhotonMapEstimator(const EstimatorSettings& settings, const EstimatorContext& context);
std::unique_ptr<Estimator> makeDetpEstimator(const EstimatorSettings& settings, const EstimatorContext& context);

// Irradiance and radiosity at every vertex of the scene's current pose, from scratch. bvh holds
// that pose. regions: the disc regions of that pose (makeDiscRegions); computed here when null
// and needed. afterFirstBounce: as EstimatorContext's.
VertexRadiosity estimateVertexRadiosity(const Scene& scene, const SceneBvh& bvh, const RayCache& cache,
                                        const EstimatorSettings& settings, const EmbreeDevice& device,
                                        const DiscRegions* regions = nullptr, bool afterFirstBounce = false);

}  // namespace qsgi
