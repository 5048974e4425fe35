// sRGB encoding of linear values for 8-bit previews (IEC 61966-2-1 transfer function).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace qsgi {

inline uint8_t encodeSrgb8(float linear) {
    const float x = std::clamp(linear, 0.0f, 1.0f);
    const float s = x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1 / 2.4f) - 0.055f;
    return uint8_t(std::lround(std::clamp(s, 0.0f, 1.0f) * 255));
}

}  // namespace qsgi
