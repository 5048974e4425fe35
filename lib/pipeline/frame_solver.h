// Frame after frame of an animation (docs/design.md §6): the first frame from scratch, then each next
// one either from scratch (--full-recompute, an estimator without an update, or a change so large
// that updating would cost more) or by the incremental update: pose the scene, find and retrace
// the paths the moved geometry affects, and hand the change to the estimator. Both give the same
// bits (fixed-point sums, identical hits). The solver knows no estimator: each owns its update.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/estimator.h"
#include "estimate/lighting_settings.h"
#include "estimate/two_pass_lighting.h"
#include "estimate/vertex_geometry.h"
#include "pipeline/update_settings.h"
#include "scene/scene.h"
#include "trace/envelope.h"
#include "trace/photon_tracer.h"
#include "trace/scene_bvh.h"
#include "trace/tracked_paths.h"
#include "util/enum_names.h"
#include "util/frame_timing.h"
#include "util/work_counter.h"

namespace qsgi {

// Each stage's own settings, as RenderSettings holds them.
struct FrameSolverSettings {
    EstimatorSettings estimator;
    TraceSettings trace;
    // Direct light from the photons or exact, and the final gather (TwoPassLighting).
    LightingSettings lighting;
    UpdateSettings update;  // frames after the first: updated or from scratch
    // coveredVertices() will be asked (the vertex fit): the vertices' start points are kept even
    // without a second pass.
    bool reportsCoveredVertices = false;
    static_assert(kTrackedGenerations == TrackedPaths::kGenerations, "update_settings.h's default is TrackedPaths' most");
};

// Why a frame after a run's first was computed from scratch, as timing.json's from_scratch_reason
// names it ("" for an updated frame and for the first frame, which is always from scratch).
enum class FromScratchReason { None, FullRecompute, EstimatorHasNoUpdate, ChangeTooLarge, NoKeptState };
inline constexpr NamedValue<FromScratchReason> kFromScratchReasonNames[] = {
    {FromScratchReason::None, ""},
    {FromScratchReason::FullRecompute, "full-recompute"},
    {FromScratchReason::EstimatorHasNoUpdate, "estimator"},  // e.g. --detp-index flann
    {FromScratchReason::ChangeTooLarge, "change-too-large"},  // judged from counts (FrameSolver::predictedUpdateShare)
    {FromScratchReason::NoKeptState, "no-kept-state"},  // the frame before kept nothing to update from
};

class FrameSolver {
public:
    // Builds the BVHs from the scene's current pose; call it before any frame is applied (the
    // rest pose), so that every run refits the same dynamic BVH whatever its first frame.
    FrameSolver(Scene& scene, const EmbreeDevice& device, const FrameSolverSettings& settings);
    ~FrameSolver();

    // A solved frame: the radiosity (valid until the next solve) and the frame's record, every
    // counter but the frame number, render and write times assembled from what each stage
    // measured and returned.
    struct Solution {
        const VertexRadiosity& radiosity;
        FrameTiming record;
    };
    // Poses the scene as the frame shows it and computes its radiosity. `updateFollows`: another
    // frame will be solved after this one; when none will (the last frame of a run), a frame
    // from scratch builds no state for updates (tracked paths, the estimator's), which would cost
    // time and, at 10^7 photons, most of the run's memory.
    Solution solve(const Pose& pose, bool updateFollows = true);
    // The next solve starts from scratch, disc regions included.
    void reset();

    // Frame 0's decision whether to build the tracking state (issue 60): `steps` are a few pairs
    // of consecutive poses sampled over the frames to come. The first frame solved from scratch
    // with updates to follow predicts, from its own photons, what updating each step would cost
    // (predictedUpdateShare, less the build that frame pays anyway); it builds the tracking state
    // only if the median step would be updated, and otherwise keeps its cache as a frame that
    // fell back does. No steps: it tracks whenever updates may follow.
    void lookAhead(std::vector<std::pair<Pose, Pose>> steps) { lookAhead_ = std::move(steps); }
    struct TrackingDecision {
        std::string decision;        // "track", "retrace", or "" (no frame was judged)
        std::vector<double> shares;  // predicted update share of each step, in order
        double median = 0;
    };
    // The last first-frame decision (empty before one is made).
    const TrackingDecision& trackingDecision() const { return decision_; }

    // Told what a solve is doing, for a progress display: the stage ("regions", "tracing",
    // "estimating", "tracking", "retracing", "updating") and, where known, how far it is (done of
    // total; total 0 when unknown). Called from the solving thread, and from worker threads a few
    // times a second while tracing, computing disc regions and estimating.
    using StageReporter = std::function<void(const char* stage, uint64_t done, uint64_t total)>;
    void reportStagesTo(StageReporter reporter) { reportStage_ = std::move(reporter); }

    const SceneBvh& bvh() const { return bvh_; }
    // The share of the lights' power that emission sends toward the scene (LightSampler).
    double emittedFraction() const { return tracer_.lights().emittedFraction(); }
    // Exact direct light, after the first solve (null with direct light from the photons).
    const DirectLight* directLight() const { return lighting_ ? &lighting_->directLight() : nullptr; }
    const DiscRegions* regions() const { return geometry_.regions(); }
    // The paths an incremental frame keeps (null unless tracking): what tests compare with a
    // fresh trace of the same pose.
    const TrackedPaths* trackedPaths() const { return tracked_.get(); }
    // The tracer, with the settings the solver gave it (emission aimed at the estimator's reach).
    const PhotonTracer& tracer() const { return tracer_; }
    // The vertices covered in the last frame's pose — inside or under closed geometry, by
    // FinalGather's rule: the gather's own flags, or without a gather the same 16 rays cast now
    // from the vertices' start points (VertexGeometry's). Only with reportsCoveredVertices or a
    // second pass, which keep the starts.
    std::vector<uint8_t> coveredVertices() const;

private:
    // What the solver holds between frames: one of these, never a mix.
    enum class Mode {
        Fresh,        // nothing solved since construction or reset(): the next frame computes
                      // everything, the per-vertex geometry included
        FromScratch,  // the last frame was computed from scratch; its ray cache is kept
                      // (lastCache_) when a frame may update from it
        Tracking,     // tracked paths and the estimator's incremental state hold the last frame
    };

    void stage(const char* name, uint64_t done = 0, uint64_t total = 0) const {
        if (reportStage_) reportStage_(name, done, total);
    }
    struct PoseChange {
        std::vector<Bounds3f> bounds;      // old and new of each instance's moved triangles
        std::vector<Bounds3f> newBounds;
        std::vector<uint8_t> vertexMoved, triangleMoved;
        std::vector<uint32_t> movedTriangles;
        bool any = false;
    };
    // Poses the scene (and its BVH) as `target` shows it; changeTo poses the scene alone.
    PoseChange pose(const Pose& target);
    PoseChange changeTo(const Pose& target);
    // The median over lookAhead_'s steps of what updating them would cost, counted in this frame's
    // tails (its trace's `segments` in all), without the tracking build (decision_ records each);
    // the scene is left posed as `current`.
    double foreseenUpdateShare(const Pose& current, const EnvelopeTails& tails, uint64_t segments);
    // Why this frame cannot or should not be updated (None: update it), and the prediction it
    // judged by (0 where none was made). `recomputed`: the vertices the estimator would recompute.
    struct Verdict {
        FromScratchReason reason = FromScratchReason::None;
        double predictedUpdateShare = 0;
    };
    Verdict judge(const PoseChange& change, size_t recomputed) const;
    // What updating to this pose would cost, in shares of a frame solved from scratch, from
    // counts alone (timing.json's predicted_update_share): the update's own work and, when the
    // last frame was solved from scratch, the tracking state it must build first.
    double predictedUpdateShare(const PoseChange& change, size_t recomputed) const;
    // Of a block of segments, those that impacted a triangle `change` moves (rule a) and those
    // passing through a mover's new bounds (rule b's candidates).
    struct AffectedCount {
        uint64_t listed = 0, nearMovers = 0;
    };
    // Sums countAffected over blocks counted on any thread (integer sums: any order, the same total).
    struct AffectedTally {
        std::atomic<uint64_t> listed{0}, nearMovers{0};
        void add(const AffectedCount& c) {
            listed += c.listed;
            nearMovers += c.nearMovers;
        }
        AffectedCount total() const { return {listed.load(), nearMovers.load()}; }
    };
    static AffectedCount countAffected(const std::vector<Segment>& block, const PoseChange& change);
    // What updating costs, as a share of a frame from scratch, for the counts of `segments` in all
    // and `recomputed` vertices: predictedUpdateShare without the tracking build.
    double updateShare(const AffectedCount& affected, uint64_t segments, size_t recomputed) const;
    // The share of a from-scratch frame that building the tracking state costs.
    double trackingBuildShare() const;
    // keepCache: a frame may update from this one (its cache is kept for the tracked paths).
    // tails, if given, receives what the tracked paths keep, found while tracing. Its stages'
    // counts and times go to the frame's record, as do startTracking's and solveIncrementally's.
    void solveFromScratch(bool keepCache, FrameTiming& record, EnvelopeTails* tails = nullptr);
    // What the tracked paths keep (the envelope of the moving geometry and how far past an impact
    // a segment counts), and where the grid that finds them lies and how fine it is.
    struct TrackingLayout {
        Envelope envelope;
        float extension = 0;
        Bounds3f gridBounds;
        float cellSize = 0;
    };
    TrackingLayout trackingLayout() const;
    // The incremental state: tracked paths and the estimator's own, from the tails this frame's
    // trace kept (tracedSegments: that trace's segment count), or else from the last frame's cache.
    void startTracking(FrameTiming& record, EnvelopeTails* tails = nullptr, uint64_t tracedSegments = 0);
    void solveIncrementally(const PoseChange& change, const std::vector<uint32_t>& recomputed, FrameTiming& record);
    // Tracking is dropped (a frame from scratch, a reset): the tracked paths and the estimator's
    // update state go together.
    void dropTracking();
    // Where the estimator's answer goes: result_ itself, or photons_ under a second pass.
    VertexRadiosity& estimate() { return lighting_ ? photons_ : result_; }
    // The second pass for this frame: from scratch the first time and under --full-recompute,
    // else brought from the last frame's. newStarts: the vertices whose start points the pose changed.
    SecondPassReport secondPass(const PoseChange& change, const std::vector<uint32_t>& newStarts, bool updateFollows);

    Scene& scene_;
    FrameSolverSettings settings_;
    StageReporter reportStage_;
    WorkCounter work_;  // the stage in progress and how far it is, for reportStage_
    SceneBvh bvh_;
    VertexGeometry geometry_;
    std::unique_ptr<Estimator> estimator_;
    PhotonTracer tracer_;  // aimed at what the estimator can count (its reach)
    // With exact direct light: the second pass, and the estimator's answer it reads (the
    // estimator updates that in place frame after frame; result_ is the combination).
    std::optional<TwoPassLighting> lighting_;
    VertexRadiosity photons_;
    Mode mode_ = Mode::Fresh;
    std::vector<Vec3f> previousPositions_;  // the moving instances' vertices before a pose
    std::vector<uint8_t> previousHidden_;   // and whether they were hidden
    // Mode::FromScratch: that frame's cache, when a frame may update from it; the tracked paths
    // are made from it only when one does (a frame that falls back to scratch again needs none).
    std::optional<RayCache> lastCache_;
    std::unique_ptr<TrackedPaths> tracked_;  // Mode::Tracking
    uint64_t foldedSegments_ = 0;            // Mode::Tracking: the cache's segments not tracked
    // Of the segments, the share the last tracking build tracked: what a build after a fallback
    // will cost, before it is made.
    double trackedShare_ = 1;
    std::vector<std::pair<Pose, Pose>> lookAhead_;
    TrackingDecision decision_;
    VertexRadiosity result_;
};

}  // namespace qsgi
