#include "trace/photon_source.h"

#include <map>
#include <optional>
#include <tuple>
#include <utility>

namespace qsgi {

PhotonSource::PhotonSource(const Scene& scene, uint64_t photons, uint64_t seed, float rayEpsilon, const EmissionAim& aim,
                           const PhotonSampling& sampling, std::shared_ptr<const SurfaceLookup> surfaces, const SceneBvh* probes)
    : seed_(seed), sampling_(sampling),
      lights_(scene, photons, rayEpsilon, aim, sampling.kind == SamplerKind::Sobol ? std::optional<uint64_t>(seed) : std::nullopt,
              probes) {
    if (!surfaces) surfaces = std::make_shared<const SurfaceLookup>(scene);
    if (surfaces->any()) lookup_ = std::move(surfaces);
    surfaceOf_.resize(scene.triangleCount());
    std::map<std::tuple<uint32_t, uint8_t, uint8_t>, uint32_t> index;  // (material, dynamic, varies) -> surface
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const uint8_t varies = lookup_ && lookup_->varies(t);
        const auto key = std::make_tuple(uint32_t(scene.triangleMaterial[t]), uint8_t(scene.triangleDynamic[t]), varies);
        auto [at, added] = index.emplace(key, uint32_t(surfaces_.size()));
        if (added) {
            const Material& m = scene.materials[std::get<0>(key)];
            surfaces_.push_back(Surface{m.albedo, maxComponent(m.albedo), std::get<1>(key), varies, m.transmission});
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
