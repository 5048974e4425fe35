// Frame after frame of an animation (DESIGN §6): the first frame from scratch, then each next
// one either from scratch (--full-recompute) or by the incremental update — retrace the paths
// the moved geometry affects, then B ← B + new − old at static vertices and a recomputation at
// the vertices the move touches. Both give the same bits (fixed-point sums, identical hits).
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "estimate/detp.h"
#include "estimate/disc_regions.h"
#include "estimate/estimator.h"
#include "estimate/impact_count.h"
#include "scene/scene.h"
#include "trace/envelope.h"
#include "trace/photon_tracer.h"
#include "trace/scene_bvh.h"
#include "trace/tracked_paths.h"

namespace qsgi {

struct FrameSolverSettings {
    EstimatorSettings estimator;
    TraceSettings trace;
    bool fullRecompute = false;  // every frame from scratch
    bool useEnvelope = true;     // false: track every path (for tests and the memory comparison)
    bool gridForBlocking = true; // false: test every tracked segment for blocking (benchmark baseline)
};

// What computing one frame cost and changed (timing.json's per-frame record).
struct FrameWork {
    bool fromScratch = false;
    double photonSeconds = 0;      // tracing, or finding and retracing affected paths
    double findSeconds = 0, retraceSeconds = 0;
    double estimationSeconds = 0;  // density estimation, disc regions included
    double discRegionsSeconds = 0;
    uint64_t discRegionsUpdated = 0;
    uint64_t segments = 0;         // in the ray cache after the frame (folded ones included)
    uint64_t photonsMissingScene = 0;
    uint64_t pathsRetraced = 0, affectedByImpact = 0, affectedByBlocking = 0, blockingCandidates = 0;
    uint64_t segmentsRemoved = 0, segmentsAdded = 0;
    uint64_t verticesUpdated = 0;
    double recomputeSeconds = 0;     // DETP: the vertices the move touched, from the segments near them
    uint64_t verticesRecomputed = 0;
    uint64_t trackedPaths = 0, trackedSegments = 0;
    uint64_t trackedBytes = 0;
};

class FrameSolver {
public:
    // Builds the BVHs from the scene's current pose; call it before any frame is applied (the
    // rest pose), so that every run refits the same dynamic BVH whatever its first frame.
    FrameSolver(Scene& scene, const EmbreeDevice& device, const FrameSolverSettings& settings);
    ~FrameSolver();

    // Poses the scene as the frame shows it and computes its radiosity.
    const VertexRadiosity& solve(const Pose& pose, FrameWork& work);
    // The next solve starts from scratch, disc regions included.
    void reset() { solved_ = regionsValid_ = false; }

    const SceneBvh& bvh() const { return bvh_; }
    // The share of the lights' power that emission sends toward the scene (LightSampler).
    double emittedFraction() const { return tracer_.lights().emittedFraction(); }
    const DiscRegions* regions() const { return regions_ ? &*regions_ : nullptr; }
    uint64_t ownSurfaceFallbacks() const { return regions_ ? regions_->fallbackVertices() : 0; }
    uint64_t buriedVertices() const { return regions_ ? regions_->buriedVertices() : 0; }

private:
    struct PoseChange {
        std::vector<uint32_t> instances;
        std::vector<Bounds3f> bounds;      // old and new of each instance's moved triangles
        std::vector<Bounds3f> newBounds;
        std::vector<uint8_t> vertexMoved, triangleMoved;
        bool any = false;
    };
    PoseChange pose(const Pose& target);
    // Vertices whose disc moved or whose regions the move touched (the moved ones without regions).
    std::vector<uint32_t> touchedVertices(const PoseChange& change) const;
    // Computes every vertex's regions the first time, afterwards only the touched ones (if given).
    void updateRegions(const std::vector<uint32_t>* touched, FrameWork& work);
    void solveFromScratch(FrameWork& work);
    void solveIncrementally(const PoseChange& change, FrameWork& work);
    // Whether the estimator keeps per-vertex sums that "+ new − old" can update; the others
    // re-estimate from every segment, so nothing can be folded.
    bool updatesSums() const;
    Vec3f detpIrradiance(uint32_t vertex, const PowerQuantizer& q) const;
    // DETP sums of the given vertices from the given segments, without an index.
    void detpBruteForceSums(const std::vector<uint32_t>& vertices, const std::vector<const Segment*>& segments,
                            const PowerQuantizer& q);

    Scene& scene_;
    const EmbreeDevice& device_;
    FrameSolverSettings settings_;
    SceneBvh bvh_;
    PhotonTracer tracer_;
    std::optional<DiscRegions> regions_;
    bool regionsValid_ = false;
    bool solved_ = false;
    std::vector<Vec3f> previousPositions_;  // the moving instances' vertices before a pose
    // Incremental state: the tracked paths and the estimator's sums.
    std::unique_ptr<TrackedPaths> tracked_;
    uint64_t foldedSegments_ = 0;
    std::vector<Segment> staticSegments_;  // untracked segments, for estimators without sums
    float maxPhotonPower_ = 0;
    std::optional<ImpactCount> impactCount_;
    std::unique_ptr<DetpDiscs> discs_;
    std::vector<DetpVertexSums> detpSums_;
    VertexRadiosity result_;
};

}  // namespace qsgi
