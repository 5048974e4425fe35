#include "estimate/estimator.h"

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

VertexRadiosity estimateVertexRadiosity(const Scene& scene, const RayCache& cache, const EstimatorSettings& settings,
                                        const EmbreeDevice& device) {
    const auto vertexOrder = [&] { return settings.sortQueries ? mortonOrder(scene.positions) : inputOrder(scene.vertexCount()); };
    VertexRadiosity out;
    switch (settings.kind) {
        case EstimatorKind::ImpactCount: {
            // Per-triangle sums need no spatial index; useIndex and sortQueries do not apply.
            ImpactCount estimator(scene);
            estimator.accumulate(cache);
            return estimator.estimate(scene, PowerQuantizer(cache.maxPhotonPower));
        }
        case EstimatorKind::PhotonMap: {
            const PhotonMap map(cache);
            out.irradiance = settings.useIndex ? map.irradiance(scene, settings.radius, settings.k, vertexOrder())
                                               : map.bruteForce(scene, settings.radius, settings.k);
            break;
        }
        case EstimatorKind::Detp: {
            if (!settings.useIndex) out.irradiance = detpBruteForce(scene, cache, settings.radius);
            else if (settings.detpIndex == DetpIndex::Flann)
                out.irradiance = detpFlannCandidates(scene, cache, settings.radius, vertexOrder());
            else
                out.irradiance = DetpDiscs(device, scene, settings.radius)
                                     .irradiance(cache, settings.sortQueries ? segmentMortonOrder(cache)
                                                                             : inputOrder(cache.segments.size()));
            break;
        }
    }
    computeRadiosity(scene, out);
    return out;
}

}  // namespace qsgi
