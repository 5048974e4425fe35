// A glTF texture image decoded from its encoded bytes: PNG with libpng under qsgi's own error
// handler, JPEG with OpenImageIO (which takes over libjpeg's messages); neither prints anything,
// so a broken texture is one warning in qsgi's words, also under --quiet. The materials read a
// texture whole (albedo and emission per texel, issue 57). tinygltf is told not to decode images at all (its decoder,
// stb_image, reads outside its input on hostile files, and it decodes every image of a file, used
// or not); gltf_document.cpp keeps the encoded bytes of URI images, and embedded images are read
// from their buffer view through the checked accessor reader. Only the textures a material uses
// are decoded.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

// Images with more pixels than this are skipped (with a warning: the material keeps its factor)
// rather than decoded; 2^28 is 16384 x 16384, past any texture a real asset ships, and decoding
// it takes seconds, while a hostile header may claim far more.
constexpr size_t kMaxTexturePixels = size_t(1) << 28;

// A texture image as stored, 8 bits a channel, RGBA: grey fills R, G and B, a missing alpha is
// 255, 16-bit values are rounded to 8 (a step of 0.4 % of the range, far below a bake's noise).
// Row 0 is the image's top row, which glTF's texture coordinate t = 0 reads. Not yet linear: a
// colour texture is sRGB-encoded, alpha and data textures are not (Texture::sample decodes).
struct TextureImage {
    uint32_t width = 0, height = 0;
    std::vector<uint8_t> rgba;
    size_t bytes() const { return rgba.capacity(); }
};

struct DecodedTexture {
    std::shared_ptr<const TextureImage> image;  // when it could be read
    std::string problem;                        // why it could not
};

// Decodes a PNG or JPEG into 4 bytes a pixel (at most kMaxTexturePixels of them: 1 GiB). Never
// throws on bad bytes and never prints: reports them (a PNG's header is checked against the PNG
// specification before libpng reads it).
// An image whose decoded pixels would need more than `budget` bytes is not decoded (the problem
// says so).
DecodedTexture decodeTextureImage(const unsigned char* bytes, size_t size, uint64_t budget = UINT64_MAX);

}  // namespace qsgi
