// Where a path's photon comes from and what its bounces do to its power: the part of tracing that
// does not depend on the pose of moving geometry (lights are static, a path's numbers are a pure
// function of its index, materials do not change). The tracer follows paths with it, and the ray
// cache decodes what it did not store with it (ray_cache.h), so both use the same arithmetic and
// get the same bits.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "scene/scene.h"
#include "scene/surface_lookup.h"
#include "trace/light_sampler.h"
#include "trace/photon_numbers.h"

namespace qsgi {

class PhotonSource {
public:
    // `surfaces`: the scene's lookup (SceneBvh::sharedSurfaces), or null to make one.
    // `probes`: the scene's BVH, with which emission decides where aiming pays (LightSampler).
    PhotonSource(const Scene& scene, uint64_t photons, uint64_t seed, float rayEpsilon, const EmissionAim& aim,
                 const PhotonSampling& sampling, std::shared_ptr<const SurfaceLookup> surfaces = nullptr,
                 const SceneBvh* probes = nullptr);

    const LightSampler& lights() const { return lights_; }
    PathNumbers numbersFor(uint64_t path) const;
    // The path's emission (power zero: a spot light's photon outside its cone, never sent).
    PhotonEmission emission(uint64_t path) const { return lights_.sample(numbersFor(path)); }

    // What a bounce reads of the triangle it hit: one 4-byte index per triangle into the few
    // distinct (material, dynamic, varies) surfaces. A 20-byte record per triangle was an 800 KB
    // table on data/cornell, and its cache misses half of the kernel's own time (three scattered
    // lookups, material index, material and dynamic flag, had been a tenth of the tracer's).
    struct Surface {
        Vec3f albedo;    // the material's, unless it varies over the triangle (surfaceAt)
        float survival;  // Russian roulette: the albedo's largest component
        uint8_t dynamic;
        uint8_t varies;  // the albedo varies over the triangle (a texture, vertex colours)
        float transmission = 0;  // the share that passes straight through, tinted by the albedo
    };
    const Surface& surface(uint32_t triangle) const { return surfaces_[surfaceOf_[triangle]]; }
    // The surface a photon meets at barycentrics (b1, b2) of `triangle`: its albedo there.
    Surface surfaceAt(uint32_t triangle, float b1, float b2) const {
        Surface s = surface(triangle);
        if (s.varies) {
            s.albedo = lookup_->albedo(triangle, b1, b2);
            s.survival = maxComponent(s.albedo);
            if (s.transmission > 0) s.transmission = lookup_->transmission(triangle, b1, b2);
        }
        return s;
    }
    // What a photon does at an impact on surface `s`, from its survival number u (the one number
    // of the bounce that decides): passes straight on (u < the transmission T: a share T passes,
    // tinted by the albedo), is reflected diffusely (the next share (1 − T)·survival), or stops.
    enum class Impact { Passes, Reflects, Stops };
    static Impact impact(const Surface& s, float u) {
        if (s.transmission > 0) {
            if (u < s.transmission) return Impact::Passes;
            u = (u - s.transmission) / (1 - s.transmission);
        }
        return u < s.survival ? Impact::Reflects : Impact::Stops;
    }
    // The power a photon carries on after an impact on surface `s` that it passed or was reflected
    // at: reflected, ρ/survival (the (1 − T) of choosing to reflect cancels); passed, the tint ρ.
    static Vec3f powerAfter(const Vec3f& power, const Surface& s, Impact what = Impact::Reflects) {
        return what == Impact::Passes ? power * s.albedo : power * s.albedo / s.survival;
    }
    // Some surface lets photons through (decoding then asks each impact there what it did).
    bool anyTransmits() const { return lookup_ && lookup_->anyTransmits(); }
    // Some triangle's albedo varies: impacts there keep where they took place.
    bool anyVaries() const { return lookup_ && lookup_->any(); }

private:
    uint64_t seed_;
    PhotonSampling sampling_;
    LightSampler lights_;
    std::shared_ptr<const SurfaceLookup> lookup_;
    std::vector<Surface> surfaces_;    // the distinct ones
    std::vector<uint32_t> surfaceOf_;  // per scene triangle
};

}  // namespace qsgi
