// Chooses where photons start (DESIGN §4): every emitter — punctual lights and each emissive
// triangle — in proportion to its power's luminance.
#pragma once

#include <vector>

#include "scene/scene.h"
#include "trace/counter_rng.h"

namespace qsgi {

struct PhotonEmission {
    Vec3f origin;
    Vec3f direction;
    Vec3f power;       // W per photon, RGB
    float originOffsetT = 0;  // tnear for the first segment (area lights: lift off the surface)
};

class LightSampler {
public:
    // photonCount is the number of photons the power is shared among.
    LightSampler(const Scene& scene, uint64_t photonCount, float rayEpsilon);

    bool empty() const { return emitters_.empty(); }
    Vec3f totalPower() const { return totalPower_; }  // W, RGB
    float maxPhotonPower() const { return maxPhotonPower_; }
    PhotonEmission sample(const PhotonRandom& rng) const;

private:
    struct Emitter {
        enum Kind { Point, Spot, Directional, Triangle } kind;
        uint32_t index;   // light or triangle index
        Vec3f power;      // W
        Vec3f photonPower;
    };
    const Scene& scene_;
    std::vector<Emitter> emitters_;
    std::vector<double> cdf_;
    Vec3f totalPower_{0.0f};
    float maxPhotonPower_ = 0;
    Vec3f boundsCentre_;
    float boundsRadius_ = 0;
    float rayEpsilon_;
};

}  // namespace qsgi
