// Chooses where photons start (docs/design.md §4): every emitter — punctual lights, each emissive
// triangle and the environment — in proportion to the power it sends toward the scene. The
// environment emits as an infinite light does in a physically based renderer: a direction in
// proportion to the map's luminance × solid angle (EnvironmentLight::sample), a point uniform on a
// disc facing it that covers the animation's bounding sphere, power L(ω) π R² / p(ω) per photon
// before the share of photons, so the photons carry π R² ∫ L dω exactly. With aiming on, point, spot
// and directional lights emit only where their projection map (projection_map.h) says photons
// may reach geometry, each photon carrying the power of the part actually sampled.
#pragma once

#include <optional>
#include <vector>

#include "scene/emission_pieces.h"
#include "scene/scene.h"
#include "trace/photon_numbers.h"
#include "trace/projection_map.h"
#include "trace/scene_bvh.h"
#include "trace/trace_settings.h"

namespace qsgi {

struct PhotonEmission {
    Vec3f origin;
    Vec3f direction;
    Vec3f power;       // W per photon, RGB; zero for a photon a spot light does not send
    float originOffsetT = 0;  // tnear for the first segment (area lights: lift off the surface)
};

class LightSampler {
public:
    // photonCount is the number of photons the power is shared among. With dealSeed, photons are
    // dealt to the emitters (dealt()) instead of each choosing one by a random number. With
    // `probes` (the scene's BVH), a point or spot light inside the scene is aimed only where its
    // map pays (aimPays()); without, every aimed light gets its map.
    LightSampler(const Scene& scene, uint64_t photonCount, float rayEpsilon, const EmissionAim& aim = {false, 0},
                 std::optional<uint64_t> dealSeed = std::nullopt, const SceneBvh* probes = nullptr);

    // Whether a map pays for a light at `apex` that emits into the cone about unit `axis` of cos
    // half-angle cosMax: kProbeRays rays spread evenly over the cone (a Fibonacci spiral, the same
    // for every run) are traced against the static geometry, and a map pays when at least
    // 1/kEscapeShare of them escape — meet neither a static triangle nor a mover's swept box. A
    // light inside a room (a lamp, a thousand lamps) then emits unaimed without building a map
    // that would keep every cell, and wastes at most about that share of its photons where a gap
    // the probes miss lets some out. Static geometry only: the answer is the same for every frame,
    // so incremental and full recomputation emit the same photons.
    // A light whose share of the photons is below kProbeRays is never aimed (nor probed).
    static constexpr int kProbeRays = 256;
    static constexpr int kEscapeShare = 64;
    static bool aimPays(const Scene& scene, const SceneBvh& bvh, const Vec3d& apex, const Vec3d& axis, double cosMax);
    // How many lights got a map, and the seconds the maps and probes took.
    size_t aimedLights() const { return aims_.size(); }
    double aimSeconds() const { return aimSeconds_; }

    bool empty() const { return emitters_.empty(); }
    // What each emitter sends toward the scene (W, RGB): punctual lights by index (zero for one
    // that sends nothing), every emissive triangle together, and the environment.
    std::vector<Vec3f> lightPowers(size_t lightCount) const;
    Vec3f emissiveTrianglePower() const;
    Vec3f environmentPower() const;
    Vec3f totalPower() const { return totalPower_; }  // W, RGB, that the emitters send
    // The luminance of what the emitters send over what they would send unaimed: the share of
    // the lights' power that can reach the scene (1 unaimed).
    double emittedFraction() const { return emittedFraction_; }
    float maxPhotonPower() const { return maxPhotonPower_; }
    PhotonEmission sample(const PathNumbers& numbers) const;

    // Dealing (the Sobol sampler): emitter e receives photons [first_e, first_{e+1}), with
    // first_e = floor(N · (share of the power before e) + φ) for one offset φ in [0, 1) drawn
    // from the seed: systematic sampling, so each emitter receives N · its share photons in
    // expectation (the photon power is unchanged and the estimate unbiased), within one of it
    // for every seed, and a light's photons are consecutive points of its own sequence.
    struct Deal {
        uint32_t emitter;
        uint32_t index;  // the photon's place among its emitter's
    };
    Deal dealt(uint64_t photon) const;  // only for a sampler built with a deal seed

private:
    // A light's projection map and the domain it covers.
    struct Aim {
        ProjectionMap map;
        Vec3d axis{0, 0, 1}, t, b;  // the cone's axis (point, spot) or the light's direction, and its basis
        double cosMax = -1;         // point, spot: the cone the map covers
        double halfSize = 0;        // directional: the square the map covers
        std::optional<Vec3d> spotAxis;  // a spot light whose cone the map does not follow
        double cosSpot = -1;
    };
    struct Emitter {
        enum Kind { Point, Spot, Directional, Triangle, Environment } kind;
        uint32_t index;   // light or triangle index (0 for the environment)
        Vec3f power;      // W, sent toward the scene
        Vec3f photonPower;
        int aim = -1;     // into aims_, −1: unaimed
        Vec3f normal{0.0f};  // a triangle's front (lights are static: worked out once, not per photon)
        int32_t piece = -1;  // a triangle's piece of constant emission (pieces_), −1: the whole triangle
    };
    void aimLight(Emitter& e, const EmissionAim& aim);
    size_t chooseEmitter(float u) const;

    const Scene& scene_;
    std::vector<Emitter> emitters_;
    std::vector<EmissionPiece> pieces_;  // the emissive textures' pieces (emission_pieces.h)
    std::vector<Aim> aims_;
    std::vector<double> cdf_;
    std::vector<uint64_t> firstPhoton_;  // dealing: per emitter, and the photon count last
    Vec3f totalPower_{0.0f};
    double emittedFraction_ = 1;
    float maxPhotonPower_ = 0;
    Vec3f boundsCentre_;
    float boundsRadius_ = 0;
    float rayEpsilon_;
    int mapDepth_ = 0;  // of every light's projection map: finer for fewer lights (mapDepthFor)
    const SceneBvh* probes_ = nullptr;
    double aimSeconds_ = 0;
};

}  // namespace qsgi
