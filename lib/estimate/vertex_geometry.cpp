#include "estimate/vertex_geometry.h"

#include <algorithm>

#include "util/stopwatch.h"

namespace qsgi {

VertexGeometry::VertexGeometry(const EstimatorSettings& estimator, bool keepsStarts) {
    if (needsDiscRegions(estimator)) regions_.emplace(makeDiscRegions(estimator));
    if (keepsStarts) starts_.emplace();
}

size_t VertexGeometry::stateBytes() const {
    return (regions_ ? regions_->keptAnswerBytes() : 0) + (starts_ ? starts_->bytes() : 0);
}

GeometryReport VertexGeometry::computeAll(const Scene& scene, const SceneBvh& bvh, WorkCounter* progress) {
    GeometryReport report;
    if (regions_) {
        Stopwatch clock;
        regions_->computeAll(scene, bvh, progress);
        reportRegions(scene.vertexCount(), clock.seconds(), report);
    }
    if (starts_) {
        Stopwatch clock;
        starts_->computeAll(scene, bvh);
        report.startsSeconds = clock.seconds();
    }
    return report;
}

GeometryChange VertexGeometry::update(const Scene& scene, const SceneBvh& bvh, const std::vector<Bounds3f>& movedBounds,
                                      const std::vector<uint8_t>& vertexMoved, WorkCounter* progress) {
    GeometryChange out;
    if (starts_) {
        Stopwatch clock;
        out.newStarts = starts_->update(scene, bvh, movedBounds, vertexMoved);
        out.report.startsSeconds = clock.seconds();
    }
    if (!regions_) {
        for (uint32_t v = 0; v < vertexMoved.size(); ++v)
            if (vertexMoved[v]) out.changed.push_back(v);
        return out;
    }
    Stopwatch clock;
    // The conservative test touches more than change: most touched vertices keep their disc.
    const std::vector<uint32_t> touched = regions_->touchedBy(scene, movedBounds, vertexMoved);
    out.changed = regions_->recompute(scene, bvh, touched, progress);
    for (uint32_t v : touched)
        if (vertexMoved[v]) out.changed.push_back(v);
    std::sort(out.changed.begin(), out.changed.end());
    out.changed.erase(std::unique(out.changed.begin(), out.changed.end()), out.changed.end());
    reportRegions(touched.size(), clock.seconds(), out.report);
    return out;
}

void VertexGeometry::reportRegions(uint64_t vertices, double seconds, GeometryReport& report) const {
    report.regionsUpdated = vertices;
    report.regionsSeconds = seconds;
    report.regionsRays = regions_->lastWork().rays;
    report.regionsStaticSkipped = regions_->lastWork().staticRaysSkipped;
    report.ownSurfacesProved = regions_->lastWork().ownSurfacesProved;
}

}  // namespace qsgi
