// A glTF texture as the materials read it (docs/inputs.md, issue 57): a decoded image, its
// sampler's wrap modes and magnification filter, and the sampling rule. Point-sampled at the
// lookup's texture coordinate — nearest texel or bilinear, as the sampler's magFilter says — and
// never mip-mapped: a mip level is a mean over a footprint the transport does not have (a photon
// hits a point; a gather ray reads a point), and would bias it.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "scene/texture_colour.h"

namespace qsgi {

struct TexCoord {
    float s = 0, t = 0;
};

// KHR_texture_transform: uv' = translation(offset) · rotation(rotation) · scale(scale) · uv.
struct UvTransform {
    float offset[2] = {0, 0};
    float rotation = 0;  // radians, counter-clockwise in UV space
    float scale[2] = {1, 1};
    bool identity() const { return offset[0] == 0 && offset[1] == 0 && rotation == 0 && scale[0] == 1 && scale[1] == 1; }
    TexCoord apply(TexCoord uv) const;
};

enum class TextureWrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

// Linear RGBA: what a texel says once decoded.
using Rgba = std::array<float, 4>;

struct Texture {
    std::shared_ptr<const TextureImage> image;  // null: the image could not be read (sampling gives white)
    TextureWrap wrapS = TextureWrap::Repeat, wrapT = TextureWrap::Repeat;
    bool nearest = false;  // magFilter NEAREST; otherwise bilinear (glTF leaves an absent filter to the reader)

    // The texture at uv: RGB through the sRGB curve when `srgb` (base colour and emissive
    // textures), as stored otherwise; alpha always as stored. Bilinear filtering interpolates the
    // decoded values.
    Rgba sample(TexCoord uv, bool srgb) const;
    size_t bytes() const { return image ? image->bytes() : 0; }
};

// How a material reads one of its textures: which one (-1: none), through which TEXCOORD set,
// transformed how.
struct TextureSlot {
    int texture = -1;
    int texCoord = 0;
    UvTransform transform;
    bool used() const { return texture >= 0; }
};

// The textures a scene's materials read, by glTF texture index (an unused one holds no image):
// shared, as a scene is copied whole and images are large.
using TextureSet = std::vector<Texture>;

}  // namespace qsgi
