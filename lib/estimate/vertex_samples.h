// A vertex's own quasi-random numbers (docs/design.md §5.1): point i of an Owen-scrambled Sobol
// sequence whose every dimension is scrambled by a hash of (seed, vertex, stream, dimension). The
// same vertex gets the same points every frame, in full recomputations and updates alike, and
// neighbouring vertices get independent scramblings, so the residual error is noise, not a
// pattern repeated over the mesh. A vertex's first 2^m points of dimensions 0 and 1 form a
// (0, m, 2)-net: shadow rays are stratified over the emitters by power, gather rays over the
// cosine-weighted hemisphere.
#pragma once

#include <cstdint>

#include "trace/counter_rng.h"
#include "trace/sobol.h"

namespace qsgi {

enum class VertexStream : uint32_t { Direct = 1, Gather = 2, Environment = 3 };

class VertexSamples {
public:
    VertexSamples(uint64_t seed, uint32_t vertex, VertexStream stream)
        : key_(mix64(mix64(seed ^ 0x5ca1ab1e0ddba11ull) ^ (uint64_t(vertex) << 8 | uint64_t(stream)))) {}

    // One dimension of the vertex's points, its scrambling drawn once: what a loop over many
    // points of the same dimension (a vertex's gather rays) reads.
    class Dimension {
    public:
        Dimension(int dimension, uint32_t scramble) : dimension_(dimension), scramble_(scramble) {}
        // Point i, in [0, 1) with 24 bits (exact as a float, never 1).
        float uniform(uint32_t i) const {
            const uint32_t x = owenScrambleReversed(SobolSequence::instance().reversedBits(i, dimension_), scramble_);
            return float(reverseBits32(x) >> 8) * 0x1p-24f;
        }

    private:
        int dimension_;
        uint32_t scramble_;
    };
    Dimension dimension(int d) const { return Dimension(d, uint32_t(mix64(key_ + uint64_t(d)))); }

    // Dimension d of point i, in [0, 1) with 24 bits (exact as a float, never 1).
    float uniform(uint32_t i, int d) const { return dimension(d).uniform(i); }

private:
    uint64_t key_;
};

}  // namespace qsgi
