#include "pipeline/frame_solver.h"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <tbb/parallel_for.h>

#include "util/stopwatch.h"

namespace qsgi {

namespace {
// The ray cache is written by every tracer thread into its own malloc arena, in blocks too small
// to be mapped apart; freed, they stay resident inside the arenas, where the tracked paths and
// estimator state growing afterwards (in other arenas) cannot use them. Handing them back keeps
// the run's peak at what it holds (data/cornell, 10^7 photons, six DETP frames: 4.17 -> 4.04 GB).
void returnFreedMemory() {
#ifdef __GLIBC__
    malloc_trim(0);
#endif
}
}  // namespace

namespace {

// Photons are aimed at what the estimator can count: as far past the geometry as a segment
// counts (Estimator::reach: DETP's discs reach r beside it, so segments passing an open edge
// cross them; the other estimators count impacts only).
TraceSettings aimedAt(TraceSettings trace, float reach) {
    trace.aim.margin = reach;
    return trace;
}

// The update's price against a from-scratch frame's, in shares of the whole. A retraced segment
// costs about what tracing and estimating it costs from scratch, and its removal about as much
// again at most; a retraced path's tail is about two segments from the one that hit the mover.
// A recomputed vertex gathers the segments around its disc, which costs a few times a vertex's
// share of a full pass. Past this share of a full frame the update is not worth it.
// A segment passing through a mover's new bounds is a candidate for rule (b): testing it costs
// about a fifth of tracing and estimating a segment (measured on data/cornell's flying block,
// 0.47 against 2.4 µs), and the few it finds blocked are retraced.
constexpr double kBlockingCandidate = 0.2;
constexpr double kSegmentsPerListedImpact = 2.0;
constexpr double kRemoveAndAdd = 2.0;
constexpr double kRecomputedVertex = 3.0;
constexpr double kWorthUpdatingBelow = 0.8;
// Building the tracking state (the tracked paths' store and index, and the estimator's own:
// DETP's remembered crossings) after a frame solved from scratch costs, per tracked segment,
// one to three times what solving it from scratch does. Measured at 10^6 photons as the build's
// share of a full frame over the share of segments tracked: DETP 0.8-1.4 (data/cornell, its
// flying block, the sweeping panel, data/tree), the walker's 1.8, impact count 3.0 on
// data/cornell (its full frame is cheap). A frame pays it whole, so the larger figure is taken.
constexpr double kTrackingBuildPerTrackedShare = 2.0;

// The stages' reports into the frame's record (timing.json's fields, docs/outputs.md).
void addEstimate(const EstimateReport& e, FrameTiming& record) {
    record.verticesUpdated = e.verticesUpdated;
    record.verticesRecomputed = e.verticesRecomputed;
    record.recomputeCandidates = e.recomputeCandidates;
    record.detpCrossings = e.detpCrossings;
    record.crossingsForgotten = e.crossingsForgotten;
    record.estimatorUpdateSeconds = e.updateSeconds;
    record.recomputeSeconds = e.recomputeSeconds;
}

void addGeometry(const GeometryReport& g, FrameTiming& record) {
    record.discRegionsSeconds = g.regionsSeconds;
    record.discRegionsUpdated = g.regionsUpdated;
    record.discRegionsRays = g.regionsRays;
    record.discRegionsStaticSkipped = g.regionsStaticSkipped;
    record.ownSurfacesProved = g.ownSurfacesProved;
}

void addSecondPass(const SecondPassReport& p, FrameTiming& record) {
    record.directSeconds += p.directSeconds;
    record.gatherSeconds = p.gatherSeconds;
    record.shadowRays = p.shadowRays;
    record.gatherRays = p.gatherRays;
    record.gatherRecords = p.gatherRecords;
}

}  // namespace

FrameSolver::FrameSolver(Scene& scene, const EmbreeDevice& device, const FrameSolverSettings& settings)
    : scene_(scene), settings_(settings),
      work_([this](const char* name, uint64_t done, uint64_t total) { stage(name, done, total); }),
      bvh_(device, scene),
      geometry_(settings.estimator, settings.lighting.exactDirect() || settings.reportsCoveredVertices),
      estimator_(Estimator::create(settings.estimator,
                                   EstimatorContext{scene_, bvh_, device, geometry_.regions(), !settings.update.fullRecompute,
                                                    &work_, settings.lighting.exactDirect()})),
      tracer_(scene, bvh_, aimedAt(settings.trace, estimator_->reach())) {
    // An auto gather cache is settled once, for the scene the run renders (its vertices do not
    // change from frame to frame), so every frame of a run, and a resumed one, uses the same.
    if (settings_.lighting.exactDirect()) lighting_.emplace(settings_.lighting.resolvedFor(scene.vertexCount()), settings_.trace.seed);
}

FrameSolver::~FrameSolver() = default;

void FrameSolver::reset() {
    mode_ = Mode::Fresh;
    if (lighting_) lighting_->reset();
    dropTracking();
    lastCache_.reset();
}

void FrameSolver::dropTracking() {
    tracked_.reset();
    estimator_->dropUpdateState();
}

FrameSolver::PoseChange FrameSolver::pose(const Pose& target) {
    PoseChange change = changeTo(target);
    if (change.any) bvh_.updateDynamic(scene_);
    return change;
}

FrameSolver::PoseChange FrameSolver::changeTo(const Pose& target) {
    PoseChange change;
    // Only instances the animation moves can move: keep their positions to compare with.
    previousPositions_.resize(scene_.vertexCount());
    previousHidden_.resize(scene_.vertexCount());
    for (const MeshInstance& inst : scene_.instances)
        if (inst.vertexCount > 0 && scene_.vertexDynamic[inst.firstVertex]) {
            std::copy_n(scene_.positions.begin() + inst.firstVertex, inst.vertexCount, previousPositions_.begin() + inst.firstVertex);
            std::copy_n(scene_.vertexHidden.begin() + inst.firstVertex, inst.vertexCount, previousHidden_.begin() + inst.firstVertex);
        }
    std::vector<uint32_t> instances;
    change.any = scene_.applyPose(target, &instances);
    // Moved is decided per vertex and triangle: an instance re-placed by a transform that leaves
    // some of its vertices where they were (a paused mover, a mesh deforming in one region)
    // moves nothing there. The bounds that later steps search are those of the moved triangles,
    // before and after: for a rigid mover its whole bounds, for a deforming mesh its moved region.
    change.vertexMoved.assign(scene_.vertexCount(), 0);
    change.triangleMoved.assign(scene_.triangleCount(), 0);
    for (uint32_t i : instances) {
        const MeshInstance& inst = scene_.instances[i];
        // A vertex hidden or shown again (a zero scale, docs/design.md §3) counts as moved even where it
        // stays put (a vertex at its node's origin): its radiosity is 0 only while hidden.
        for (uint32_t v = inst.firstVertex; v < inst.firstVertex + inst.vertexCount; ++v)
            change.vertexMoved[v] = std::memcmp(&previousPositions_[v], &scene_.positions[v], sizeof(Vec3f)) != 0 ||
                                    previousHidden_[v] != scene_.vertexHidden[v];
        Bounds3f before, after;
        for (uint32_t t = inst.firstTriangle; t < inst.firstTriangle + inst.triangleCount; ++t) {
            for (uint32_t v : scene_.triangles[t].v) change.triangleMoved[t] |= change.vertexMoved[v];
            if (!change.triangleMoved[t]) continue;
            change.movedTriangles.push_back(t);
            for (uint32_t v : scene_.triangles[t].v) {
                before.extend(previousPositions_[v]);
                after.extend(scene_.positions[v]);
            }
        }
        if (after.empty()) continue;  // re-placed, yet nothing moved
        change.bounds.push_back(before);
        change.bounds.push_back(after);
        change.newBounds.push_back(after);
    }
    std::sort(change.movedTriangles.begin(), change.movedTriangles.end());
    return change;
}

double FrameSolver::foreseenUpdateShare(const Pose& current, const EnvelopeTails& tails, uint64_t segments) {
    decision_.shares.clear();
    // A hidden vertex keeps the last normal a visible pose gave it (Scene::applyPose): the steps
    // must not leave theirs on the vertices hidden now, which the frame's files carry.
    const std::vector<Vec3f> normals = scene_.normals;
    for (const auto& [from, to] : lookAhead_) {
        changeTo(from);
        const PoseChange change = changeTo(to);
        // A segment that meets no part of the envelope can neither impact a mover nor pass
        // through one in any frame: the tails hold every segment the count can find.
        AffectedTally affected;
        if (change.any)
            tbb::parallel_for(size_t(0), tails.blocks.size(), [&](size_t b) { affected.add(countAffected(tails.blocks[b], change)); });
        // The vertices that moved are recomputed at least; the disc regions a move changes
        // beside them are not known without computing them, so the count is a lower bound.
        const size_t moved = size_t(std::count(change.vertexMoved.begin(), change.vertexMoved.end(), uint8_t(1)));
        decision_.shares.push_back(updateShare(affected.total(), segments, moved));
    }
    changeTo(current);  // the same pose, the same bits: the BVH was never moved from it
    scene_.normals = normals;
    std::vector<double> sorted = decision_.shares;
    std::sort(sorted.begin(), sorted.end());
    decision_.median = sorted.empty() ? 0 : sorted[sorted.size() / 2];
    return decision_.median;
}

double FrameSolver::trackingBuildShare() const {
    return mode_ == Mode::Tracking ? 0.0 : kTrackingBuildPerTrackedShare * trackedShare_;
}

double FrameSolver::predictedUpdateShare(const PoseChange& change, size_t recomputed) const {
    // Segments that impacted a moved triangle (rule a) and segments passing through a mover's
    // new bounds (rule b's candidates): from the index once tracking (the entries of the cells
    // the new bounds overlap, a bound on the candidates), counted in the last frame's cache
    // before (a scan, far cheaper than either way of computing the frame).
    AffectedCount affected;
    uint64_t segments = 0;
    if (mode_ == Mode::Tracking) {
        affected.listed = tracked_->segmentsListedOn(change.movedTriangles);
        affected.nearMovers = tracked_->entriesNear(change.newBounds);
        segments = foldedSegments_ + tracked_->trackedSegments();
    } else {
        segments = lastCache_->segmentCount();
        AffectedTally tally;
        lastCache_->forEachBlock([&](size_t, const std::vector<Segment>& block) { tally.add(countAffected(block, change)); });
        affected = tally.total();
    }
    return updateShare(affected, segments, recomputed) + trackingBuildShare();
}

FrameSolver::AffectedCount FrameSolver::countAffected(const std::vector<Segment>& block, const PoseChange& change) {
    AffectedCount counted;
    for (const Segment& s : block) {
        counted.listed += s.hasImpact() && s.impactDynamic && change.triangleMoved[s.triangle];
        counted.nearMovers += rayMeetsAny(change.newBounds, s.origin, s.direction, double(s.length));
    }
    return counted;
}

double FrameSolver::updateShare(const AffectedCount& affected, uint64_t segments, size_t recomputed) const {
    const double perSegment = 1.0 / double(std::max<uint64_t>(segments, 1));
    const double segmentShare = double(affected.listed) * kSegmentsPerListedImpact * kRemoveAndAdd * perSegment +
                                double(affected.nearMovers) * kBlockingCandidate * perSegment;
    const double vertexShare = double(recomputed) * kRecomputedVertex / double(std::max<size_t>(scene_.vertexCount(), 1));
    return segmentShare + vertexShare;
}

FrameSolver::Verdict FrameSolver::judge(const PoseChange& change, size_t recomputed) const {
    Verdict verdict;
    if (settings_.update.fullRecompute) verdict.reason = FromScratchReason::FullRecompute;
    else if (!estimator_->canUpdate()) verdict.reason = FromScratchReason::EstimatorHasNoUpdate;
    else if (mode_ == Mode::FromScratch && !lastCache_) verdict.reason = FromScratchReason::NoKeptState;
    else if (change.any && !settings_.update.alwaysUpdate && mode_ == Mode::FromScratch &&
             trackingBuildShare() > kWorthUpdatingBelow) {
        // The build alone would cost more than the frame: no count can make the update worth it,
        // so the cache is not scanned for one.
        verdict.predictedUpdateShare = trackingBuildShare();
        verdict.reason = FromScratchReason::ChangeTooLarge;
    } else if (change.any) {
        verdict.predictedUpdateShare = predictedUpdateShare(change, recomputed);
        if (!settings_.update.alwaysUpdate && verdict.predictedUpdateShare > kWorthUpdatingBelow)
            verdict.reason = FromScratchReason::ChangeTooLarge;
    }
    return verdict;
}

FrameSolver::Solution FrameSolver::solve(const Pose& target, bool updateFollows) {
    FrameTiming record;
    const PoseChange change = pose(target);
    Stopwatch clock;
    work_.start("regions", 0);
    const bool firstFrame = mode_ == Mode::Fresh;
    GeometryChange geometry;  // what the pose change left different (nothing on a first frame)
    if (firstFrame) geometry.report = geometry_.computeAll(scene_, bvh_, &work_);
    else if (change.any) geometry = geometry_.update(scene_, bvh_, change.bounds, change.vertexMoved, &work_);
    addGeometry(geometry.report, record);
    const std::vector<uint32_t> recomputed = estimator_->verticesToRecompute(geometry.changed, change.vertexMoved);
    // The start points are the second pass's: their time is counted with direct light's.
    const double regionSeconds = clock.seconds() - geometry.report.startsSeconds;
    record.directSeconds = geometry.report.startsSeconds;

    const Verdict verdict = firstFrame ? Verdict{} : judge(change, recomputed.size());
    const FromScratchReason why = verdict.reason;
    record.predictedUpdateShare = verdict.predictedUpdateShare;
    if (firstFrame || why != FromScratchReason::None) {
        // A frame may update from this one only if one follows and could.
        const bool updatesMayFollow = updateFollows && !settings_.update.fullRecompute && estimator_->canUpdate();
        // After the first frame the tracking state is made at once, from the tails its trace
        // kept (no second look at the cache, which is then not kept), so that the frames after
        // it pay only their updates; after a fallback, only once a frame updates again, from
        // the kept cache, and that frame's price includes it.
        if (firstFrame && updatesMayFollow) {
            const TrackingLayout layout = trackingLayout();
            EnvelopeTails tails{layout.envelope, layout.extension, {}};
            // The steps are judged from the tails, before the tracking state is built from them.
            // Judged not worth it, the cache is kept instead, as after a fallback: the frames
            // after are judged from it, and one worth updating builds the state then.
            const bool judged = !lookAhead_.empty() && !settings_.update.alwaysUpdate;
            solveFromScratch(judged, record, &tails);
            if (judged) {
                Stopwatch clock;
                const bool track = foreseenUpdateShare(target, tails, record.segments) <= kWorthUpdatingBelow;
                decision_.decision = track ? "track" : "retrace";
                record.predictedUpdateShare = decision_.median;
                record.photonSimulationSeconds += clock.seconds();
                if (track) {
                    lastCache_.reset();  // not held beside the tracking state while it is built
                    startTracking(record, &tails, record.segments);
                } else {
                    // What a build would track, for the later frames' verdicts: the tails.
                    uint64_t tailSegments = 0;
                    for (const std::vector<Segment>& block : tails.blocks) tailSegments += block.size();
                    trackedShare_ = double(tailSegments) / double(std::max<uint64_t>(record.segments, 1));
                }
            } else {
                decision_ = {"track", {}, 0};
                startTracking(record, &tails, record.segments);
            }
        } else {
            solveFromScratch(updatesMayFollow, record);
        }
        record.fromScratchReason = nameOf(kFromScratchReasonNames, why);
    } else {
        record.fromScratch = false;
        if (change.any) {
            if (mode_ == Mode::FromScratch) startTracking(record);
            solveIncrementally(change, recomputed, record);
        } else if (mode_ == Mode::FromScratch && updateFollows && trackingBuildShare() <= kWorthUpdatingBelow) {
            // Nothing moved, so nothing changes; a frame that costs nothing else is the time to
            // build the tracking state, if that costs less than a frame (else the next update
            // pays for it, or falls back).
            startTracking(record);
        }
    }
    record.estimationSeconds += regionSeconds;
    if (lighting_) addSecondPass(secondPass(change, geometry.newStarts, updateFollows), record);
    if (mode_ == Mode::Tracking) {
        record.trackedPaths = tracked_->trackedPaths();
        record.trackedSegments = tracked_->trackedSegments();
        record.trackedBytes = tracked_->bytes();
        record.segments = foldedSegments_ + tracked_->trackedSegments();
    }
    // The per-vertex geometry's kept static answers are incremental state too.
    record.estimatorStateBytes = estimator_->stateBytes() + geometry_.stateBytes() + (lighting_ ? lighting_->stateBytes() : 0);
    if (const DiscRegions* regions = geometry_.regions()) {
        record.ownSurfaceFallbacks = regions->fallbackVertices();
        record.buriedVertices = regions->buriedVertices();
    }
    return Solution{result_, std::move(record)};
}

void FrameSolver::solveFromScratch(bool keepCache, FrameTiming& record, EnvelopeTails* tails) {
    record.fromScratch = true;
    mode_ = Mode::FromScratch;
    dropTracking();
    lastCache_.reset();
    Stopwatch clock;
    work_.start("tracing", settings_.trace.photons);
    RayCache cache = tracer_.traceAll(&work_, tails);
    record.photonSimulationSeconds = clock.seconds();
    record.segments = cache.segmentCount();
    record.photonsMissingScene = tracer_.lights().empty() ? 0 : cache.pathsMissingScene();
    record.pathsRetraced = cache.pathCount();
    record.segmentsAdded = cache.segmentCount();

    clock.restart();
    work_.start("estimating", 0);
    addEstimate(estimator_->solve(cache, estimate()), record);
    record.estimationSeconds = clock.seconds();
    if (keepCache) lastCache_ = std::move(cache);
}

FrameSolver::TrackingLayout FrameSolver::trackingLayout() const {
    // Paths that meet the envelope are tracked, the rest stay folded into the estimator's state.
    TrackingLayout layout;
    const float reach = estimator_->reach();
    const float margin = envelopeMargin(reach > 0, reach, scene_.sceneEpsilon());
    layout.envelope = settings_.update.useEnvelope ? Envelope::ofAnimation(scene_, margin) : Envelope::everything();
    layout.extension = reach;
    layout.gridBounds = layout.envelope.isEverything() ? scene_.animationBounds.expanded(margin) : layout.envelope.bounds();
    // The grid answers two kinds of query: the movers' new bounds (rule (b)) and, for DETP, the
    // discs a frame recomputes. For the first, cells an eighth of the envelope across are fine
    // and cheap to fill (measured on data/cornell: the impact-count update 2.0x -> 2.5x against
    // 32 divisions); discs want cells a few discs across, no more than 32 along an axis. The
    // whole scene (no envelope) gets half as many.
    const float divisions = (reach > 0 ? 32.0f : 8.0f) / (layout.envelope.isEverything() ? 2.0f : 1.0f);
    layout.cellSize = std::max(4 * reach, layout.gridBounds.extent() / divisions);
    return layout;
}

void FrameSolver::startTracking(FrameTiming& record, EnvelopeTails* tails, uint64_t tracedSegments) {
    stage("tracking");
    Stopwatch clock;
    const uint32_t generations = settings_.update.trackedGenerations;
    const TrackingLayout layout = trackingLayout();
    uint64_t segments = 0;
    if (tails) {
        segments = tracedSegments;
        tracked_ = std::make_unique<TrackedPaths>(tracer_.source(), *tails, layout.gridBounds, layout.cellSize, generations);
    } else {
        const RayCache& cache = *lastCache_;
        segments = cache.segmentCount();
        tracked_ = std::make_unique<TrackedPaths>(cache, layout.envelope, layout.extension, layout.gridBounds, layout.cellSize,
                                                  generations);
    }
    foldedSegments_ = segments - tracked_->trackedSegments();
    trackedShare_ = double(tracked_->trackedSegments()) / double(std::max<uint64_t>(segments, 1));
    record.photonSimulationSeconds += clock.seconds();
    clock.restart();
    estimator_->prepareUpdates(*tracked_);
    record.estimationSeconds += clock.seconds();
    lastCache_.reset();
    mode_ = Mode::Tracking;
    returnFreedMemory();
}

void FrameSolver::solveIncrementally(const PoseChange& change, const std::vector<uint32_t>& recomputed, FrameTiming& record) {
    Stopwatch clock;
    stage("retracing");
    const AffectedPaths affected =
        tracked_->findAffected(change.movedTriangles, change.triangleMoved, change.newBounds, bvh_, settings_.update.gridForBlocking);
    record.findAffectedSeconds += affected.seconds;
    record.impactCandidates += affected.impactCandidates;
    record.blockingCandidates += affected.blockingCandidates;
    record.pathsAffectedByImpact += affected.byImpact;
    record.pathsAffectedByBlocking += affected.byBlockingOnly;
    Stopwatch retrace;
    PathChanges changes;
    tracked_->retrace(affected.paths, tracer_, changes);
    record.retraceSeconds += retrace.seconds();
    record.pathsRetraced += affected.paths.size();
    record.segmentsRemoved += changes.removed.size();
    record.segmentsAdded += changes.added.size();
    record.photonSimulationSeconds += clock.seconds();

    clock.restart();
    const FrameChange frameChange{changes.removed,         changes.added, change.vertexMoved, change.triangleMoved,
                                  change.movedTriangles, recomputed,    *tracked_};
    stage("updating");
    addEstimate(estimator_->update(frameChange, estimate()), record);
    record.estimationSeconds += clock.seconds();
}

}  // namespace qsgi

namespace qsgi {

SecondPassReport FrameSolver::secondPass(const PoseChange& change, const std::vector<uint32_t>& newStarts, bool updateFollows) {
    const VertexStarts& starts = *geometry_.starts();
    if (!lighting_->solved() || settings_.update.fullRecompute) {
        // Keep what an update reads only if one may come.
        const bool keep = updateFollows && !settings_.update.fullRecompute;
        return lighting_->solve(scene_, bvh_, starts, photons_, result_, &work_, keep);
    }
    stage("gathering");
    return lighting_->update(scene_, bvh_, starts, newStarts, MovedGeometry{change.bounds, change.vertexMoved}, photons_, result_);
}

std::vector<uint8_t> FrameSolver::coveredVertices() const {
    if (lighting_ && !lighting_->covered().empty()) return lighting_->covered();
    const VertexStarts* starts = geometry_.starts();
    if (!starts) throw std::logic_error("FrameSolver::coveredVertices: asked without reportsCoveredVertices or a second pass");
    return FinalGather(FinalGather::kCoverRays, settings_.trace.seed).castCovered(scene_, bvh_, *starts);
}

}  // namespace qsgi
