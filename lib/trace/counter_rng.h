// Counter-based random numbers (docs/design.md §4): the numbers of photon i, bounce k, dimension d are a
// pure function of (seed, i, k, d). Retracing a path repeats its choices exactly, and results do
// not depend on thread count or scheduling.
#pragma once

#include <cstdint>

namespace qsgi {

// SplitMix64's finaliser: a bijective 64-bit mix with full avalanche.
constexpr uint64_t mix64(uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

class PhotonRandom {
public:
    PhotonRandom(uint64_t seed, uint64_t photon) : key_(mix64(mix64(seed + 0x9E3779B97F4A7C15ull) ^ photon)) {}

    // Uniform in [0, 1) with 24 random bits (every value exactly representable as float).
    float uniform(uint32_t bounce, uint32_t dimension) const {
        const uint64_t h = mix64(key_ ^ mix64((uint64_t(bounce) << 32) | dimension));
        return float(h >> 40) * 0x1p-24f;
    }

private:
    uint64_t key_;
};

// Dimensions used at each bounce. Bounce 0 is the emission; bounce k > 0 is the scattering at the
// impact of segment k-1. Under the Sobol sampler (photon_numbers.h) photons are dealt to lights
// and aimed maps sampled from the direction pair, so kLightChoice and kEmitCell go unused there.
namespace rng_dim {
constexpr uint32_t kLightChoice = 0, kEmitPosition0 = 1, kEmitPosition1 = 2, kEmitDirection0 = 3, kEmitDirection1 = 4;
constexpr uint32_t kEmitCell = 5;  // a projection map's cell (aimed emission)
constexpr uint32_t kSurvival = 0, kScatterDirection0 = 1, kScatterDirection1 = 2;
}  // namespace rng_dim

}  // namespace qsgi
