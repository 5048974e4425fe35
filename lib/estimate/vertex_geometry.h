// The per-vertex geometry that every estimator and the second pass share (docs/design.md §5, §5.1):
// each vertex's own surface and disc regions, and its start point s_v, for the scene's current
// pose. It has one owner, this class, which computes it for the first frame and brings it to each
// new pose, and says which vertices the pose change left different. Estimators, the second pass
// and the covered-vertex rule only read it; what each estimator keeps besides (DETP's sums, the
// photon map's lists) is its own.
//
// Each part is held only where something reads it: disc regions when the estimator reads them
// (DETP's boundary rules, the photon map), start points (VertexStarts) when rays leave the
// vertices (the second pass, or the covered vertices the vertex fit asks for). The discs'
// regions have a start of their own (DiscRegions: the paper's lift by ε_v⁺ toward a cell), a
// different point for a different question.
#pragma once

#include <optional>
#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/estimator.h"
#include "estimate/vertex_starts.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/work_counter.h"

namespace qsgi {

// What computing or updating the geometry measured, for the frame's record.
struct GeometryReport {
    double regionsSeconds = 0;
    uint64_t regionsUpdated = 0;          // vertices whose regions were (re)computed
    uint64_t regionsRays = 0;             // rays they traced (DiscRegions::Work)
    uint64_t regionsStaticSkipped = 0;    // vertices whose static rays needed no asking
    uint64_t ownSurfacesProved = 0;       // vertices whose ε⁺ OwnSurfaceTree proved without the walk
    double startsSeconds = 0;
};

// An update's answer: what the pose change left different, and what it took.
struct GeometryChange {
    // Sorted: the moved vertices and those whose regions may now decide differently (what
    // estimators recompute: Estimator::verticesToRecompute).
    std::vector<uint32_t> changed;
    // Increasing: the vertices whose start point or normal changed (VertexStarts::update).
    std::vector<uint32_t> newStarts;
    GeometryReport report;
};

class VertexGeometry {
public:
    // keepsStarts: rays leave the vertices (the second pass, the covered-vertex rule).
    VertexGeometry(const EstimatorSettings& estimator, bool keepsStarts);

    // Every vertex, for the scene's current pose (bvh holds it).
    GeometryReport computeAll(const Scene& scene, const SceneBvh& bvh, WorkCounter* progress);
    // After a pose change: recomputes the vertices whose test region the moved objects' old or
    // new bounds (`movedBounds`) touch, and the moved vertices, and the start points within
    // their reach.
    GeometryChange update(const Scene& scene, const SceneBvh& bvh, const std::vector<Bounds3f>& movedBounds,
                          const std::vector<uint8_t>& vertexMoved, WorkCounter* progress);

    // The regions (null when the estimator reads none).
    const DiscRegions* regions() const { return regions_ ? &*regions_ : nullptr; }
    // The start points (null unless kept).
    const VertexStarts* starts() const { return starts_ ? &*starts_ : nullptr; }

    // Bytes of incremental state: the static answers kept for recomputed vertices, the starts.
    size_t stateBytes() const;

private:
    // The regions' work of this frame, into the report.
    void reportRegions(uint64_t vertices, double seconds, GeometryReport& report) const;

    std::optional<DiscRegions> regions_;
    std::optional<VertexStarts> starts_;
};

}  // namespace qsgi
