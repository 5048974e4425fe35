#include "trace/photon_source.h"

#include <map>
#include <optional>
#include <utility>

namespace qsgi {

PhotonSource::PhotonSource(const Scene& scene, uint64_t photons, uint64_t seed, float rayEpsilon, const EmissionAim& aim,
                           const PhotonSampling& sampling)
    : seed_(seed), sampling_(sampling),
      lights_(scene, photons, rayEpsilon, aim,
              sampling.kind == SamplerKind::Sobol ? std::optional<uint64_t>(seed) : std::nullopt) {
    surfaceOf_.resize(scene.triangleCount());
    std::map<std::pair<uint32_t, uint8_t>, uint32_t> index;  // (material, dynamic) -> surface
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const auto key = std::make_pair(uint32_t(scene.triangleMaterial[t]), uint8_t(scene.triangleDynamic[t]));
        auto [at, added] = index.emplace(key, uint32_t(surfaces_.size()));
        if (added) {
            const Vec3f albedo = scene.materials[key.first].albedo;
            surfaces_.push_back(Surface{albedo, maxComponent(albedo), key.second});
        }
        surfaceOf_[t] = at->second;
    }
}

PathNumbers PhotonSource::numbersFor(uint64_t path) const {
    if (sampling_.kind == SamplerKind::Random) return PathNumbers(seed_, path);
    const LightSampler::Deal deal = lights_.dealt(path);
    return PathNumbers(seed_, path, deal.emitter, deal.index, sampling_.qmcBounces);
}

}  // namespace qsgi
