// The uniform numbers one photon path draws (docs/design.md §4, issue 20). Every number is a pure function
// of (seed, photon, bounce, dimension), so retracing a path repeats its choices exactly and
// results do not depend on threads, frame ranges or Slurm chunks. Two samplers:
//  - random: every number hashed (counter_rng.h), independent of every other;
//  - sobol: the emission and the survival and direction of the first K scatterings are the
//    coordinates of an Owen-scrambled Sobol point (sobol.h), so a light's photons stratify the
//    directions (and positions) it emits in, and their first bounces; later numbers stay hashed.
//    Each emitter has its own sequence, scrambled independently: photons are dealt to emitters
//    in proportion to their power (LightSampler), emitter e's j-th photon taking point j of its
//    sequence, so every light's photons are a prefix of a (t, s)-sequence whatever the others do.
//
// The Sobol dimensions: 0, 1 (a (0,2)-sequence, t = 0) decide the emission's main pair (a
// punctual or area light's direction, a directional light's position); 2, 3 an area light's
// position; scattering k = 1..K reads survival from 4 + 3(k−1) and direction from the pair after.
#pragma once

#include <algorithm>
#include <cstdint>

#include "trace/counter_rng.h"
#include "trace/sobol.h"
#include "trace/trace_settings.h"

namespace qsgi {

constexpr uint32_t kSobolEmissionDimensions = 4;
constexpr uint32_t kSobolDimensionsPerBounce = 3;
static_assert(kMaxQmcBounces == (SobolSequence::kDimensions - kSobolEmissionDimensions) / kSobolDimensionsPerBounce,
              "kMaxQmcBounces (trace_settings.h) is the scatterings the shipped table can cover");

class PathNumbers {
public:
    // Hashed everywhere (the random sampler): exactly the numbers qsgi drew before Sobol.
    PathNumbers(uint64_t seed, uint64_t photon) : hashed_(seed, photon) {}
    // Point `index` of emitter `emitter`'s scrambled sequence for the emission and the first
    // qmcBounces scatterings (at most kMaxQmcBounces: the table's dimensions), hashed beyond.
    PathNumbers(uint64_t seed, uint64_t photon, uint32_t emitter, uint32_t index, uint32_t qmcBounces)
        : hashed_(seed, photon), sobol_(&SobolSequence::instance()), scrambleKey_(mix64(mix64(seed ^ 0x50B01A5EEDull) + emitter)),
          emitter_(emitter), index_(index), qmcBounces_(std::min(qmcBounces, kMaxQmcBounces)) {}

    // Whether the light was chosen by dealing (Sobol) rather than by a number (random).
    bool dealt() const { return sobol_ != nullptr; }
    uint32_t emitter() const { return emitter_; }

    // Uniform in [0, 1) with 24 bits (every value exactly representable as float).
    float uniform(uint32_t bounce, uint32_t dimension) const {
        const int d = sobolDimension(bounce, dimension);
        return d < 0 ? hashed_.uniform(bounce, dimension) : float(scrambled(d) >> 8) * 0x1p-24f;
    }
    // The same number with 32 bits where it is a Sobol coordinate (a projection map spends the
    // leading bits choosing a cell and the rest placing the photon in it).
    double wide(uint32_t bounce, uint32_t dimension) const {
        const int d = sobolDimension(bounce, dimension);
        return d < 0 ? double(hashed_.uniform(bounce, dimension)) : double(scrambled(d)) * 0x1p-32;
    }

    // The Sobol dimension a (bounce, dimension) number is, or −1 for a hashed one.
    int sobolDimension(uint32_t bounce, uint32_t dimension) const {
        using namespace rng_dim;
        if (!sobol_) return -1;
        if (bounce == 0) {
            switch (dimension) {
                case kEmitDirection0: return 0;
                case kEmitDirection1: return 1;
                case kEmitPosition0: return 2;
                case kEmitPosition1: return 3;
                default: return -1;
            }
        }
        if (bounce > qmcBounces_ || dimension > kScatterDirection1) return -1;
        return int(kSobolEmissionDimensions + kSobolDimensionsPerBounce * (bounce - 1) + dimension);
    }

private:
    uint32_t scrambled(int d) const {
        const uint32_t seed = uint32_t(mix64(scrambleKey_ ^ (uint64_t(d) + 1) * 0x9E3779B97F4A7C15ull));
        return reverseBits32(owenScrambleReversed(sobol_->reversedBits(index_, d), seed));
    }

    PhotonRandom hashed_;
    const SobolSequence* sobol_ = nullptr;  // null: the random sampler
    uint64_t scrambleKey_ = 0;
    uint32_t emitter_ = 0, index_ = 0, qmcBounces_ = 0;
};

}  // namespace qsgi
