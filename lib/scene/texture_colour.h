// The mean colour of a glTF texture image, decoded from its encoded bytes: PNG with libpng under
// qsgi's own error handler, JPEG with OpenImageIO (which takes over libjpeg's messages); neither
// prints anything, so a broken texture is one warning in qsgi's words, also under --quiet.
//
// qsgi's surfaces are Lambertian with one albedo per material, so a base colour texture counts
// only through its mean linear colour. tinygltf is told not to decode images at all (its decoder,
// stb_image, reads outside its input on hostile files, and it decodes every image of a file, used
// or not); gltf_document.cpp keeps the encoded bytes of URI images, and embedded images are read
// from their buffer view through the checked accessor reader. Only the textures a material uses
// are decoded, a scanline at a time, so memory stays at one row whatever the image's size.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "util/vecmath.h"

namespace qsgi {

// Images with more pixels than this are skipped (with a warning: the material keeps its factor)
// rather than decoded; 2^28 is 16384 x 16384, past any texture a real asset ships, and decoding
// it takes seconds, while a hostile header may claim far more.
constexpr size_t kMaxTexturePixels = size_t(1) << 28;

struct TextureColour {
    std::optional<Vec3f> mean;  // mean linear (sRGB-decoded) RGB, when the image could be read
    std::string problem;        // why it could not, for the warning
};

// Decodes a PNG or JPEG (the formats glTF 2.0 allows) from memory and averages its pixels after
// the sRGB transfer function; grey images give grey. Never throws on bad bytes and never prints:
// reports them (a PNG's header is checked against the PNG specification before libpng reads it).
TextureColour meanTextureColour(const unsigned char* bytes, size_t size);

}  // namespace qsgi
