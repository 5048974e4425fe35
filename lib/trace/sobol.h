// A counter-based, Owen-scrambled Sobol sequence (issue 20): point i of dimension d is computed
// from i alone (no sequential state), so a photon's numbers are a pure function of its index,
// as the hashed ones are (docs/design.md §4). Direction numbers are Joe and Kuo's (sobol_table.h); the
// scrambling is Burley's hash-based Owen scrambling ("Practical Hash-based Owen Scrambling",
// JCGT 9(4), 2020), which keeps every (t, m, s)-net a net with the same t.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "trace/sobol_table.h"

namespace qsgi {

constexpr uint32_t reverseBits32(uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

class SobolSequence {
public:
    static constexpr int kDimensions = kSobolDimensions;

    // Direction numbers of every dimension, built once from the table.
    static const SobolSequence& instance();

    // Dimension d (0-based; 0 is van der Corput) of point `index`, as 32 bits of [0, 1), bit-
    // reversed (the leading bit of the fraction is bit 0): the form owenScrambleReversed takes.
    uint32_t reversedBits(uint32_t index, int dimension) const {
        const std::array<uint32_t, 32>& v = reversedDirections_[std::size_t(dimension)];
        uint32_t x = 0;
        // One step per set bit of the index: a branch per bit, mispredicted half the time, made
        // the tracer a quarter slower.
        for (; index; index &= index - 1) x ^= v[std::size_t(__builtin_ctz(index))];
        return x;
    }
    uint32_t bits(uint32_t index, int dimension) const { return reverseBits32(reversedBits(index, dimension)); }

private:
    SobolSequence();
    // V_j = m_j · 2^(32−j), j = 1..32, each bit-reversed.
    std::array<std::array<uint32_t, 32>, kDimensions> reversedDirections_;
};

// Owen scrambling of a 32-bit fraction by a 32-bit seed: each bit is flipped by a function of the
// seed and of the bits above it only (on the reversed bits, adding and xor-ing with even
// multiples carry information only upward: Laine and Karras' observation, Burley's constants).
// Points that share their leading k bits still do after it, so elementary intervals map to
// elementary intervals and nets stay nets. Takes and returns the fraction bit-reversed.
constexpr uint32_t owenScrambleReversed(uint32_t reversed, uint32_t seed) {
    uint32_t x = reversed + seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

}  // namespace qsgi
