#include "estimate/estimator.h"

#include <optional>

namespace qsgi {

bool needsDiscRegions(const EstimatorSettings& s) {
    return s.kind != EstimatorKind::ImpactCount && s.detp.boundary != DetpBoundary::Paper;
}

std::vector<uint32_t> movedOnly(const std::vector<uint32_t>& vertices, const std::vector<uint8_t>& vertexMoved) {
    std::vector<uint32_t> moved;
    for (uint32_t v : vertices)
        if (vertexMoved[v]) moved.push_back(v);
    return moved;
}

DiscRegions makeDiscRegions(const EstimatorSettings& s) { return DiscRegions(s.radius, s.kind == EstimatorKind::PhotonMap); }

std::unique_ptr<Estimator> Estimator::create(const EstimatorSettings& settings, const EstimatorContext& context) {
    switch (settings.kind) {
        case EstimatorKind::ImpactCount: return makeImpactCountEstimator(settings, context);
        case EstimatorKind::PhotonMap: return makePhotonMapEstimator(settings, context);
        case EstimatorKind::Detp: return makeDetpEstimator(settings, context);
    }
    return nullptr;
}

VertexRadiosity estimateVertexRadiosity(const Scene& scene, const SceneBvh& bvh, const RayCache& cache,
                                        const EstimatorSettings& settings, const EmbreeDevice& device,
                                        const DiscRegions* regions, bool afterFirstBounce) {
    std::optional<DiscRegions> own;
    if (needsDiscRegions(settings) && !regions) {
        own.emplace(makeDiscRegions(settings));
        own->computeAll(scene, bvh);
        regions = &*own;
    }
    if (!needsDiscRegions(settings)) regions = nullptr;
    VertexRadiosity out;
    EstimatorContext context{scene, bvh, device, regions};
    context.afterFirstBounce = afterFirstBounce;
    Estimator::create(settings, context)->solve(cache, out);
    return out;
}

}  // namespace qsgi
