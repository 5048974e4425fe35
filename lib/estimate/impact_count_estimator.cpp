// Impact count behind the Estimator interface: per-triangle fixed-point sums, so an update is
// bookkeeping — the removed impacts leave their triangles, the added ones join theirs, and only
// the vertices of those triangles and of moved ones are averaged again.
#include <algorithm>

#include "estimate/estimator.h"
#include "estimate/impact_count.h"

namespace qsgi {

namespace {

class ImpactCountEstimator final : public Estimator {
public:
    ImpactCountEstimator(const EstimatorContext& context)
        : scene_(context.scene), sums_(context.scene, context.afterFirstBounce), afterFirstBounce_(context.afterFirstBounce) {}

    EstimateReport solve(const RayCache& cache, VertexRadiosity& out) override {
        quantizer_ = PowerQuantizer(cache.maxPhotonPower);
        sums_.updateGeometry(scene_);
        sums_.accumulate(cache);
        out = sums_.estimate(scene_, quantizer_);
        EstimateReport report;
        report.verticesUpdated = scene_.vertexCount();
        return report;
    }

    float reach() const override { return 0.0f; }  // an impact counts where it lands
    // Reads no disc regions: only a moved vertex counts differently.
    std::vector<uint32_t> verticesToRecompute(const std::vector<uint32_t>& changed,
                                              const std::vector<uint8_t>& vertexMoved) const override {
        return movedOnly(changed, vertexMoved);
    }
    void prepareUpdates(const TrackedPaths&) override {}

    EstimateReport update(const FrameChange& change, VertexRadiosity& out) override {
        // Old segments leave with the facing they were counted with, before the triangles move.
        for (const Segment& s : change.removed) sums_.subtract(s, quantizer_);
        const std::vector<uint32_t>& moved = change.movedTriangles;
        sums_.updateGeometry(scene_, moved);
        for (const Segment& s : change.added) sums_.add(s, quantizer_);
        // The vertices of the triangles whose sums or areas changed are averaged again.
        std::vector<uint8_t> changed(scene_.vertexCount(), 0);
        auto mark = [&](uint32_t t) {
            for (uint32_t v : scene_.triangles[t].v) changed[v] = 1;
        };
        for (uint32_t t : moved) mark(t);
        // A segment left out (bounce 0, after the first bounce only) changed no sum.
        for (const auto* list : {&change.removed, &change.added})
            for (const Segment& s : *list)
                if (s.hasImpact() && !(afterFirstBounce_ && !s.scattered)) mark(s.triangle);
        std::vector<uint32_t> vertices;
        for (uint32_t v = 0; v < scene_.vertexCount(); ++v)
            if (changed[v]) vertices.push_back(v);
        sums_.estimateAt(scene_, quantizer_, vertices, out);
        EstimateReport report;
        report.verticesUpdated = vertices.size();
        return report;
    }

private:
    const Scene& scene_;
    ImpactCount sums_;
    bool afterFirstBounce_;  // segments of bounce 0 count nowhere (ImpactCount leaves them out)
    PowerQuantizer quantizer_{0.0f};
};

}  // namespace

std::unique_ptr<Estimator> makeImpactCountEstimator(const EstimatorSettings&, const EstimatorContext& context) {
    return std::make_unique<ImpactCountEstimator>(context);
}

}  // namespace qsgi
