#include "pipeline/frame_solver.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>

#include "estimate/morton_order.h"
#include "util/stopwatch.h"

namespace qsgi {

namespace {

// Photons are aimed at what the estimator can count: DETP's discs reach r beside the geometry
// (segments passing an open edge cross them); the other estimators count impacts only.
TraceSettings aimedAtEstimator(TraceSettings trace, const EstimatorSettings& e) {
    trace.aim.margin = e.kind == EstimatorKind::Detp ? e.radius : 0.0f;
    return trace;
}

}  // namespace

FrameSolver::FrameSolver(Scene& scene, const EmbreeDevice& device, const FrameSolverSettings& settings)
    : scene_(scene), device_(device), settings_(settings), bvh_(device, scene),
      tracer_(scene, bvh_, aimedAtEstimator(settings.trace, settings.estimator)) {
    if (needsDiscRegions(settings_.estimator)) regions_.emplace(makeDiscRegions(settings_.estimator));
}

FrameSolver::~FrameSolver() = default;

bool FrameSolver::updatesSums() const {
    const EstimatorSettings& e = settings_.estimator;
    return e.kind == EstimatorKind::ImpactCount || (e.kind == EstimatorKind::Detp && e.detpIndex == DetpIndex::Embree);
}

FrameSolver::PoseChange FrameSolver::pose(const Pose& target) {
    PoseChange change;
    // Only instances the animation moves can move: keep their positions to compare with.
    previousPositions_.resize(scene_.vertexCount());
    for (const MeshInstance& inst : scene_.instances)
        if (inst.vertexCount > 0 && scene_.vertexDynamic[inst.firstVertex])
            std::copy_n(scene_.positions.begin() + inst.firstVertex, inst.vertexCount, previousPositions_.begin() + inst.firstVertex);
    change.any = scene_.applyPose(target, &change.instances);
    // Moved is decided per vertex and triangle: an instance re-placed by a transform that leaves
    // some of its vertices where they were (a paused mover, a mesh deforming in one region)
    // moves nothing there. The bounds that later steps search are those of the moved triangles,
    // before and after: for a rigid mover its whole bounds, for a deforming mesh its moved region.
    change.vertexMoved.assign(scene_.vertexCount(), 0);
    change.triangleMoved.assign(scene_.triangleCount(), 0);
    for (uint32_t i : change.instances) {
        const MeshInstance& inst = scene_.instances[i];
        for (uint32_t v = inst.firstVertex; v < inst.firstVertex + inst.vertexCount; ++v)
            change.vertexMoved[v] = std::memcmp(&previousPositions_[v], &scene_.positions[v], sizeof(Vec3f)) != 0;
        Bounds3f before, after;
        for (uint32_t t = inst.firstTriangle; t < inst.firstTriangle + inst.triangleCount; ++t) {
            for (uint32_t v : scene_.triangles[t].v) change.triangleMoved[t] |= change.vertexMoved[v];
            if (!change.triangleMoved[t]) continue;
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
    if (change.any) bvh_.updateDynamic(scene_);
    return change;
}

std::vector<uint32_t> FrameSolver::touchedVertices(const PoseChange& change) const {
    if (regions_) return regions_->touchedBy(scene_, change.bounds, change.vertexMoved);
    std::vector<uint32_t> moved;
    for (uint32_t v = 0; v < scene_.vertexCount(); ++v)
        if (change.vertexMoved[v]) moved.push_back(v);
    return moved;
}

void FrameSolver::updateRegions(const std::vector<uint32_t>* touched, FrameWork& work) {
    if (!regions_) return;
    Stopwatch clock;
    if (!regionsValid_) {
        regions_->computeAll(scene_, bvh_);
        work.discRegionsUpdated = scene_.vertexCount();
        regionsValid_ = true;
    } else if (touched) {
        regions_->recompute(scene_, bvh_, *touched);
        work.discRegionsUpdated = touched->size();
    }
    work.discRegionsSeconds = clock.seconds();
}

const VertexRadiosity& FrameSolver::solve(const Pose& target, FrameWork& work) {
    work = FrameWork();
    const PoseChange change = pose(target);
    if (!solved_ || settings_.fullRecompute) {
        Stopwatch clock;
        const std::vector<uint32_t> touched = regionsValid_ && change.any ? touchedVertices(change) : std::vector<uint32_t>();
        updateRegions(regionsValid_ && change.any ? &touched : nullptr, work);
        const double regionSeconds = clock.seconds();
        solveFromScratch(work);
        work.estimationSeconds += regionSeconds;
        solved_ = true;
    } else {
        solveIncrementally(change, work);
    }
    if (tracked_) {
        work.trackedPaths = tracked_->trackedPaths();
        work.trackedSegments = tracked_->trackedSegments();
        work.trackedBytes = tracked_->bytes();
        work.segments = foldedSegments_ + tracked_->trackedSegments();
    }
    return result_;
}

void FrameSolver::solveFromScratch(FrameWork& work) {
    work.fromScratch = true;
    Stopwatch clock;
    const RayCache cache = tracer_.traceAll();
    work.photonSeconds = clock.seconds();
    work.segments = cache.segments.size();
    work.photonsMissingScene = tracer_.lights().empty() ? 0 : cache.pathsMissingScene();
    work.pathsRetraced = cache.pathCount();
    work.segmentsAdded = cache.segments.size();
    maxPhotonPower_ = cache.maxPhotonPower;

    clock.restart();
    const EstimatorSettings& e = settings_.estimator;
    const PowerQuantizer q(cache.maxPhotonPower);
    if (e.kind == EstimatorKind::ImpactCount) {
        impactCount_.emplace(scene_);
        impactCount_->accumulate(cache);
        result_ = impactCount_->estimate(scene_, q);
    } else if (updatesSums()) {
        if (e.useIndex) {
            if (!discs_) discs_ = std::make_unique<DetpDiscs>(device_, scene_, e.radius, e.boundary, regions(), &bvh_);
            discs_->updateDynamic();
            detpSums_ = discs_->sums(cache, e.sortQueries ? segmentMortonOrder(cache) : inputOrder(cache.segments.size()));
        } else {
            std::vector<const Segment*> all(cache.segments.size());
            for (size_t i = 0; i < all.size(); ++i) all[i] = &cache.segments[i];
            detpSums_.assign(scene_.vertexCount(), DetpVertexSums());
            detpBruteForceSums(inputOrder(scene_.vertexCount()), all, q);
        }
        result_.irradiance.resize(scene_.vertexCount());
        for (uint32_t v = 0; v < scene_.vertexCount(); ++v) result_.irradiance[v] = detpIrradiance(v, q);
        computeRadiosity(scene_, result_);
    } else {
        result_ = estimateVertexRadiosity(scene_, bvh_, cache, e, device_, regions());
    }
    work.estimationSeconds = clock.seconds();
    work.verticesUpdated = scene_.vertexCount();

    if (settings_.fullRecompute) return;
    // The incremental state: paths that meet the envelope are tracked, the rest folded into the
    // sums just computed (estimators that re-estimate from every segment track everything).
    const bool discs = e.kind != EstimatorKind::ImpactCount;
    const float margin = envelopeMargin(discs, e.radius, scene_.sceneEpsilon());
    // The photon map keeps the untracked segments (they never change) to re-estimate from.
    const bool sums = updatesSums();
    const Envelope envelope = settings_.useEnvelope ? Envelope::ofAnimation(scene_, sums ? margin : scene_.sceneEpsilon())
                                                    : Envelope::everything();
    const Bounds3f gridBounds = envelope.isEverything() ? scene_.animationBounds.expanded(margin) : envelope.bounds();
    // Cells a few discs across, no more than 32 along an axis (16 for the whole scene): queries
    // ask about objects' bounds, and finer cells cost more to fill than they save.
    const float cellSize = std::max(discs ? 4 * e.radius : 0.0f, gridBounds.extent() / (envelope.isEverything() ? 16 : 32));
    staticSegments_.clear();
    tracked_ = std::make_unique<TrackedPaths>(cache, envelope, sums && discs ? e.radius : 0.0f, gridBounds, cellSize,
                                              sums ? nullptr : &staticSegments_);
    foldedSegments_ = cache.segments.size() - tracked_->trackedSegments();
}

Vec3f FrameSolver::detpIrradiance(uint32_t v, const PowerQuantizer& q) const {
    const EstimatorSettings& e = settings_.estimator;
    return detpVertexIrradiance(detpSums_[v], regions_ ? &(*regions_)[v] : nullptr, e.radius, e.boundary, q);
}

void FrameSolver::detpBruteForceSums(const std::vector<uint32_t>& vertices, const std::vector<const Segment*>& segments,
                                     const PowerQuantizer& q) {
    const EstimatorSettings& e = settings_.estimator;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, vertices.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i)
            detpSums_[vertices[i]] = detpVertexSums(scene_, vertices[i], segments, e.radius, e.boundary, regions(), &bvh_, q);
    });
}

void FrameSolver::solveIncrementally(const PoseChange& change, FrameWork& work) {
    if (!change.any) return;  // nothing moved: no path changes, no vertex changes
    PathChanges changes;
    const std::vector<AffectedPath> affected =
        tracked_->findAffected(change.triangleMoved, change.newBounds, bvh_, settings_.gridForBlocking, changes);
    tracked_->retrace(affected, tracer_, changes);
    work.findSeconds = changes.findSeconds;
    work.retraceSeconds = changes.retraceSeconds;
    work.photonSeconds = changes.findSeconds + changes.retraceSeconds;
    work.pathsRetraced = changes.pathsRetraced;
    work.affectedByImpact = changes.affectedByImpact;
    work.affectedByBlocking = changes.affectedByBlocking;
    work.blockingCandidates = changes.blockingCandidates;
    work.segmentsRemoved = changes.removed.size();
    work.segmentsAdded = changes.added.size();

    Stopwatch clock;
    // Vertices whose disc moved or whose regions the move touched.
    const std::vector<uint32_t> touched = touchedVertices(change);
    updateRegions(&touched, work);
    const EstimatorSettings& e = settings_.estimator;
    const PowerQuantizer q(maxPhotonPower_);
    if (e.kind == EstimatorKind::ImpactCount) {
        // Old segments leave with the facing they were counted with, before the triangles move.
        for (const Segment& s : changes.removed) impactCount_->subtract(s, q);
        impactCount_->updateGeometry(scene_);
        for (const Segment& s : changes.added) impactCount_->add(s, q);
        result_ = impactCount_->estimate(scene_, q);
        std::vector<uint8_t> updated(scene_.vertexCount(), 0);
        auto mark = [&](uint32_t t) {
            for (uint32_t v : scene_.triangles[t].v) updated[v] = 1;
        };
        for (const auto* list : {&changes.removed, &changes.added})
            for (const Segment& s : *list)
                if (s.hasImpact()) mark(s.triangle);
        for (uint32_t t = 0; t < scene_.triangleCount(); ++t)
            if (change.triangleMoved[t]) mark(t);
        work.verticesUpdated = uint64_t(std::count(updated.begin(), updated.end(), uint8_t(1)));
    } else if (updatesSums()) {
        // Vertices whose disc moved or whose regions the move touched are recomputed from the
        // tracked segments near them; every other vertex takes + new − old.
        const std::vector<uint32_t>& recompute = touched;
        std::vector<uint8_t> skip(scene_.vertexCount(), 0);
        for (uint32_t v : recompute) skip[v] = 1;
        std::vector<uint32_t> changed;
        if (e.useIndex) {
            discs_->updateDynamic();
            discs_->accumulate(changes.removed, q, -1, skip, detpSums_, changed);
            discs_->accumulate(changes.added, q, +1, skip, detpSums_, changed);
        } else {
            // Index-free (--no-ray-cache): every changed segment against every disc.
            std::vector<const Segment*> removed, added;
            for (const Segment& s : changes.removed) removed.push_back(&s);
            for (const Segment& s : changes.added) added.push_back(&s);
            std::vector<uint8_t> touched(scene_.vertexCount(), 0);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, scene_.vertexCount(), 64), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t v = r.begin(); v != r.end(); ++v) {
                    if (skip[v]) continue;
                    const DetpVertexSums delta = detpVertexSums(scene_, uint32_t(v), added, e.radius, e.boundary, regions(), &bvh_, q);
                    const DetpVertexSums gone = detpVertexSums(scene_, uint32_t(v), removed, e.radius, e.boundary, regions(), &bvh_, q);
                    if (delta == DetpVertexSums() && gone == DetpVertexSums()) continue;
                    detpSums_[v] += delta;
                    detpSums_[v] -= gone;
                    touched[v] = 1;
                }
            });
            for (uint32_t v = 0; v < scene_.vertexCount(); ++v)
                if (touched[v]) changed.push_back(v);
        }
        Stopwatch recomputeClock;
        for (uint32_t v : recompute) detpSums_[v] = DetpVertexSums();
        if (e.useIndex) {
            // The tracked segments near any recomputed disc, gathered once from the grid (every
            // such disc lies within the envelope margin of a moved object's old or new bounds),
            // then traced through the disc BVH counting only the recomputed vertices.
            const float margin = envelopeMargin(true, e.radius, scene_.sceneEpsilon());
            std::vector<const Segment*> near;
            for (const Bounds3f& b : change.bounds) tracked_->segmentsNear(b.expanded(margin), near);
            std::sort(near.begin(), near.end());
            near.erase(std::unique(near.begin(), near.end()), near.end());
            std::vector<Segment> segments(near.size());
            for (size_t i = 0; i < near.size(); ++i) segments[i] = *near[i];
            discs_->recompute(segments, q, recompute, detpSums_);
        } else {
            std::vector<const Segment*> all;
            tracked_->allSegments(all);
            detpBruteForceSums(recompute, all, q);
        }
        work.recomputeSeconds = recomputeClock.seconds();
        work.verticesRecomputed = recompute.size();
        changed.insert(changed.end(), recompute.begin(), recompute.end());
        std::sort(changed.begin(), changed.end());
        changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
        for (uint32_t v : changed) result_.irradiance[v] = detpIrradiance(v, q);
        computeRadiosity(scene_, result_);
        work.verticesUpdated = changed.size();
    } else {
        // The photon map's k nearest neighbours cannot be folded (DESIGN §6.5): re-estimate from
        // every segment, the untracked ones kept as they were.
        RayCache all;
        all.maxPhotonPower = maxPhotonPower_;
        all.segments = staticSegments_;
        tracked_->appendAll(all.segments);
        result_ = estimateVertexRadiosity(scene_, bvh_, all, e, device_, regions());
        work.verticesUpdated = scene_.vertexCount();
    }
    work.estimationSeconds = clock.seconds();
}

}  // namespace qsgi
