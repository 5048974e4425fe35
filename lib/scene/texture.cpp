#include "scene/texture.h"

#include <algorithm>
#include <cmath>

namespace qsgi {
namespace {

// The sRGB curve of the glTF specification, for every 8-bit value (a table built once: a pow
// per lookup would be most of a photon bounce's cost).
const std::array<float, 256>& srgbTable() {
    static const std::array<float, 256> table = [] {
        std::array<float, 256> t{};
        for (size_t v = 0; v < t.size(); ++v) {
            const double c = double(v) / 255.0;
            t[v] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
        }
        return t;
    }();
    return table;
}

// Texel index along an axis of `size` texels for the (unbounded) texel coordinate i.
int64_t wrapped(int64_t i, int64_t size, TextureWrap wrap) {
    switch (wrap) {
    case TextureWrap::ClampToEdge: return std::clamp<int64_t>(i, 0, size - 1);
    case TextureWrap::MirroredRepeat: {
        const int64_t period = 2 * size, m = ((i % period) + period) % period;
        return m < size ? m : period - 1 - m;
    }
    case TextureWrap::Repeat: break;
    }
    return ((i % size) + size) % size;
}

// A texel coordinate kept within ±2^40 texels: a hostile UV of 1e30 (or a non-finite one) still
// names a texel, and int64 arithmetic never overflows.
double bounded(double x) { return std::isfinite(x) ? std::clamp(x, -1e12, 1e12) : 0.0; }

}  // namespace

TexCoord UvTransform::apply(TexCoord uv) const {
    const float c = std::cos(rotation), s = std::sin(rotation);
    const float x = uv.s * scale[0], y = uv.t * scale[1];
    // The extension's matrix (its GLSL, column-major mat3(c, s, 0, −s, c, 0, 0, 0, 1), as the
    // Khronos sample viewer applies it): s' = c·s − sin·t, t' = sin·s + c·t.
    return {c * x - s * y + offset[0], s * x + c * y + offset[1]};
}

Rgba Texture::sample(TexCoord uv, bool srgb) const {
    if (!image || image->width == 0 || image->height == 0) return {1, 1, 1, 1};
    const std::array<float, 256>& curve = srgbTable();
    const int64_t w = image->width, h = image->height;
    auto texel = [&](int64_t x, int64_t y) {
        const uint8_t* p = image->rgba.data() + 4 * size_t(wrapped(y, h, wrapT) * w + wrapped(x, w, wrapS));
        Rgba out;
        for (size_t c = 0; c < 3; ++c) out[c] = srgb ? curve[p[c]] : float(p[c]) / 255.0f;
        out[3] = float(p[3]) / 255.0f;
        return out;
    };
    const double x = bounded(double(uv.s) * double(w)), y = bounded(double(uv.t) * double(h));
    if (nearest) return texel(int64_t(std::floor(x)), int64_t(std::floor(y)));
    // Bilinear about texel centres.
    const double fx = x - 0.5, fy = y - 0.5;
    const int64_t x0 = int64_t(std::floor(fx)), y0 = int64_t(std::floor(fy));
    const float ax = float(fx - double(x0)), ay = float(fy - double(y0));
    const Rgba a = texel(x0, y0), b = texel(x0 + 1, y0), c = texel(x0, y0 + 1), d = texel(x0 + 1, y0 + 1);
    Rgba out;
    for (size_t k = 0; k < 4; ++k)
        out[k] = (a[k] * (1 - ax) + b[k] * ax) * (1 - ay) + (c[k] * (1 - ax) + d[k] * ax) * ay;
    return out;
}

}  // namespace qsgi
