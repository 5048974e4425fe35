#include "estimate/estimator.h"

#include <optional>

#include "estimate/detp.h"
#include "estimate/impact_count.h"
#include "estimate/morton_order.h"
#include "estimate/photon_map.h"

namespace qsgi {

const char* estimatorName(EstimatorKind kind) {
    switch (kind) {
        case EstimatorKind::ImpactCount: return "impact-count";
        case EstimatorKind::PhotonMap: return "photon-map";
        case EstimatorKind::Detp: return "detp";
    }
    return "?";
}

bool needsDiscRegions(const EstimatorSettings& s) {
    return s.kind != EstimatorKind::ImpactCount && s.boundary != DetpBoundary::Paper;
}

DiscRegions makeDiscRegions(const EstimatorSettings& s) { return DiscRegions(s.radius, s.kind == EstimatorKind::PhotonMap); }

VertexRadiosity estimateVertexRadiosity(const Scene& scene, const SceneBvh& bvh, const RayCache& cache,
                                        const EstimatorSettings& settings, const EmbreeDevice& device,
                                        const DiscRegions* regions) {
    const auto vertexOrder = [&] { return settings.sortQueries ? mortonOrder(scene.positions) : inputOrder(scene.vertexCount()); };
    std::optional<DiscRegions> own;
    if (needsDiscRegions(settings) && !regions) {
        own.emplace(makeDiscRegions(settings));
        own->computeAll(scene, bvh);
        regions = &*own;
    }
    if (!needsDiscRegions(settings)) regions = nullptr;
    const DetpBoundary rule = settings.boundary;
    VertexRadiosity out;
    switch (settings.kind) {
        case EstimatorKind::ImpactCount: {
            // Per-triangle sums need no spatial index; useIndex and sortQueries do not apply.
            ImpactCount estimator(scene);
            estimator.accumulate(cache);
            return estimator.estimate(scene, PowerQuantizer(cache.maxPhotonPower));
        }
        case EstimatorKind::PhotonMap: {
            const PhotonMap map(cache, scene, &bvh);
            out.irradiance = settings.useIndex ? map.irradiance(scene, regions, settings.radius, settings.k, vertexOrder())
                                               : map.bruteForce(scene, regions, settings.radius, settings.k);
            break;
        }
        case EstimatorKind::Detp: {
            if (!settings.useIndex) out.irradiance = detpBruteForce(scene, cache, settings.radius, rule, regions, &bvh);
            else if (settings.detpIndex == DetpIndex::Flann)
                out.irradiance = detpFlannCandidates(scene, cache, settings.radius, rule, regions, &bvh, vertexOrder());
            else
                out.irradiance = DetpDiscs(device, scene, settings.radius, rule, regions, &bvh)
                                     .irradiance(cache, settings.sortQueries ? segmentMortonOrder(cache)
                                                                             : inputOrder(cache.segments.size()));
            break;
        }
    }
    computeRadiosity(scene, out);
    return out;
}

}  // namespace qsgi
