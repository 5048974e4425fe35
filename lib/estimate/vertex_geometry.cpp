#include "estimate/vertex_geometry.h"

#include <algorithm>

#include "util/stopwatch.h"

namespace qsgi {

VertexGeometry::VertexGeometry(const EstimatorSettings& estimator) {
    if (needsDiscRegions(estimator)) regions_.emplace(makeDiscRegions(estimator));
}

void VertexGeometry::computeAll(const Scene& scene, const SceneBvh& bvh, WorkCounter* progress, FrameTiming& stats) {
    if (!regions_) return;
    Stopwatch clock;
    regions_->computeAll(scene, bvh, progress);
    recordWork(scene.vertexCount(), clock.seconds(), stats);
}

std::vector<uint32_t> VertexGeometry::update(const Scene& scene, const SceneBvh& bvh, const std::vector<Bounds3f>& movedBounds,
                                             const std::vector<uint8_t>& vertexMoved, WorkCounter* progress,
                                             FrameTiming& stats) {
    std::vector<uint32_t> changed;
    if (!regions_) {
        for (uint32_t v = 0; v < vertexMoved.size(); ++v)
            if (vertexMoved[v]) changed.push_back(v);
        return changed;
    }
    Stopwatch clock;
    // The conservative test touches more than change: most touched vertices keep their disc.
    const std::vector<uint32_t> touched = regions_->touchedBy(scene, movedBounds, vertexMoved);
    changed = regions_->recompute(scene, bvh, touched, progress);
    for (uint32_t v : touched)
        if (vertexMoved[v]) changed.push_back(v);
    std::sort(changed.begin(), changed.end());
    changed.erase(std::unique(changed.begin(), changed.end()), changed.end());
    recordWork(touched.size(), clock.seconds(), stats);
    return changed;
}

void VertexGeometry::recordWork(uint64_t vertices, double seconds, FrameTiming& stats) const {
    stats.discRegionsUpdated = vertices;
    stats.discRegionsSeconds = seconds;
    stats.discRegionsRays = regions_->lastWork().rays;
    stats.discRegionsStaticSkipped = regions_->lastWork().staticRaysSkipped;
    stats.ownSurfacesProved = regions_->lastWork().ownSurfacesProved;
}

void VertexGeometry::report(FrameTiming& stats) const {
    if (!regions_) return;
    stats.ownSurfaceFallbacks = regions_->fallbackVertices();
    stats.buriedVertices = regions_->buriedVertices();
}

}  // namespace qsgi
