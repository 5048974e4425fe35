#include "trace/sobol.h"

namespace qsgi {

const SobolSequence& SobolSequence::instance() {
    static const SobolSequence sequence;  // immutable once built; C++ makes the first build thread-safe
    return sequence;
}

SobolSequence::SobolSequence() {
    std::array<std::array<uint32_t, 32>, kDimensions> directions;
    // Dimension 0: van der Corput, every m_j = 1.
    for (int j = 0; j < 32; ++j) directions[0][std::size_t(j)] = 1u << (31 - j);
    for (int d = 1; d < kDimensions; ++d) {
        const JoeKuoRow& row = kJoeKuoRows[d - 1];
        const int s = row.degree;
        std::array<uint32_t, 32>& v = directions[std::size_t(d)];
        for (int j = 0; j < 32; ++j) {
            if (j < s) {
                v[std::size_t(j)] = uint32_t(row.initial[j]) << (31 - j);
                continue;
            }
            // Bratley and Fox's recurrence: V_j = V_{j−s} ⊕ (V_{j−s} >> s) ⊕ Σ_k a_k V_{j−k}.
            uint32_t x = v[std::size_t(j - s)] ^ (v[std::size_t(j - s)] >> s);
            for (int k = 1; k < s; ++k)
                if ((row.inner >> (s - 1 - k)) & 1) x ^= v[std::size_t(j - k)];
            v[std::size_t(j)] = x;
        }
    }
    for (int d = 0; d < kDimensions; ++d)
        for (int j = 0; j < 32; ++j) reversedDirections_[std::size_t(d)][std::size_t(j)] = reverseBits32(directions[std::size_t(d)][std::size_t(j)]);
}

}  // namespace qsgi
