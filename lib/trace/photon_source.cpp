#include "trace/photon_source.h"

#include <optional>

namespace qsgi {

PhotonSource::PhotonSource(const Scene& scene, uint64_t photons, uint64_t seed, float rayEpsilon, const EmissionAim& aim,
                           const PhotonSampling& sampling)
    : seed_(seed), sampling_(sampling),
      lights_(scene, photons, rayEpsilon, aim,
              sampling.kind == SamplerKind::Sobol ? std::optional<uint64_t>(seed) : std::nullopt) {
    surfaces_.resize(scene.triangleCount());
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Vec3f albedo = scene.materials[scene.triangleMaterial[t]].albedo;
        surfaces_[t] = Surface{albedo, maxComponent(albedo), scene.triangleDynamic[t]};
    }
}

PathNumbers PhotonSource::numbersFor(uint64_t path) const {
    if (sampling_.kind == SamplerKind::Random) return PathNumbers(seed_, path);
    const LightSampler::Deal deal = lights_.dealt(path);
    return PathNumbers(seed_, path, deal.emitter, deal.index, sampling_.qmcBounces);
}

}  // namespace qsgi
