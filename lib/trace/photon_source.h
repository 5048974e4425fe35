// Where a path's photon comes from and what its bounces do to its power: the part of tracing that
// does not depend on the pose of moving geometry (lights are static, a path's numbers are a pure
// function of its index, materials do not change). The tracer follows paths with it, and the ray
// cache decodes what it did not store with it (ray_cache.h), so both use the same arithmetic and
// get the same bits.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"
#include "trace/light_sampler.h"
#include "trace/photon_numbers.h"

namespace qsgi {

class PhotonSource {
public:
    PhotonSource(const Scene& scene, uint64_t photons, uint64_t seed, float rayEpsilon, const EmissionAim& aim,
                 const PhotonSampling& sampling);

    const LightSampler& lights() const { return lights_; }
    PathNumbers numbersFor(uint64_t path) const;
    // The path's emission (power zero: a spot light's photon outside its cone, never sent).
    PhotonEmission emission(uint64_t path) const { return lights_.sample(numbersFor(path)); }

    // What a bounce reads of the triangle it hit: one 4-byte index per triangle into the few
    // distinct (material, dynamic) surfaces. A 20-byte record per triangle was an 800 KB table
    // on data/cornell, and its cache misses half of the kernel's own time (three scattered
    // lookups, material index, material and dynamic flag, had been a tenth of the tracer's).
    struct Surface {
        Vec3f albedo;
        float survival;  // Russian roulette: the albedo's largest component
        uint8_t dynamic;
    };
    const Surface& surface(uint32_t triangle) const { return surfaces_[surfaceOf_[triangle]]; }
    // The power a photon carries on after surviving an impact on `triangle`.
    Vec3f powerAfter(const Vec3f& power, uint32_t triangle) const {
        const Surface& s = surface(triangle);
        return power * s.albedo / s.survival;
    }

private:
    uint64_t seed_;
    PhotonSampling sampling_;
    LightSampler lights_;
    std::vector<Surface> surfaces_;    // the distinct ones
    std::vector<uint32_t> surfaceOf_;  // per scene triangle
};

}  // namespace qsgi
