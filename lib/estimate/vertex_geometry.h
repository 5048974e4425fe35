// The per-vertex geometry that every estimator and the second pass share (docs/design.md §5, §5.1):
// each vertex's own surface, start point s_v and disc regions, for the scene's current pose. It has
// one owner, this class, which computes it for the first frame and brings it to each new pose,
// and says which vertices the pose change left different. Estimators and the second pass only
// read it; what each estimator keeps besides (DETP's sums, the photon map's lists) is its own.
//
// It holds disc regions when the estimator reads them (DETP's boundary rules, the photon map),
// nothing otherwise: the second pass's rays start from the vertices themselves (VertexStarts).
#pragma once

#include <optional>
#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/estimator.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/frame_timing.h"
#include "util/work_counter.h"

namespace qsgi {

class VertexGeometry {
public:
    explicit VertexGeometry(const EstimatorSettings& estimator);

    // Every vertex, for the scene's current pose (bvh holds it).
    void computeAll(const Scene& scene, const SceneBvh& bvh, WorkCounter* progress, FrameTiming& stats);
    // After a pose change: recomputes the vertices whose test region the moved objects' old or
    // new bounds (`movedBounds`) touch, and the moved vertices. Returns, sorted, the moved
    // vertices and those whose regions may now decide differently: what estimators recompute
    // (Estimator::verticesToRecompute).
    std::vector<uint32_t> update(const Scene& scene, const SceneBvh& bvh, const std::vector<Bounds3f>& movedBounds,
                                 const std::vector<uint8_t>& vertexMoved, WorkCounter* progress, FrameTiming& stats);

    // The regions (null when the estimator reads none).
    const DiscRegions* regions() const { return regions_ ? &*regions_ : nullptr; }

    // Bytes of incremental state (the static answers kept for recomputed vertices), and the
    // counts timing.json reports.
    size_t stateBytes() const { return regions_ ? regions_->keptAnswerBytes() : 0; }
    void report(FrameTiming& stats) const;

private:
    // The regions' time, vertices and work of this frame, into timing.json's fields.
    void recordWork(uint64_t vertices, double seconds, FrameTiming& stats) const;

    std::optional<DiscRegions> regions_;
};

}  // namespace qsgi
