// Rounding without a library call where a hot loop rounds many values.
#pragma once

#include <cstdint>

namespace qsgi {

// std::lround(x) for x in [0, 65535]: x + 0.5 is exact in double (x has 24 significant bits and
// is below 2^16, or is so small that the sum rounds to 0.5 and truncates to 0, as lround gives),
// so truncating the sum rounds halves away from zero, as lround does. Tested against lround at
// every half-integer and its neighbouring floats.
inline uint16_t roundToUint16(float x) { return uint16_t(int(double(x) + 0.5)); }

}  // namespace qsgi
