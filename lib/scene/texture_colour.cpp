#include "scene/texture_colour.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstring>
#include <vector>

namespace qsgi {
namespace {

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// The container's signature decides the reader (the mimeType and the file name may lie); OIIO
// picks its plugin by the name's extension, so the name handed to it is only "texture.png" or
// "texture.jpg".
const char* extensionOf(const unsigned char* bytes, size_t size) {
    static const unsigned char png[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static const unsigned char jpeg[3] = {0xFF, 0xD8, 0xFF};
    if (size >= sizeof png && std::memcmp(bytes, png, sizeof png) == 0) return "png";
    if (size >= sizeof jpeg && std::memcmp(bytes, jpeg, sizeof jpeg) == 0) return "jpg";
    return nullptr;
}

// A PNG's chunks (length, type, data, CRC) must all lie inside the bytes and end with IEND. libpng
// says the same of a truncated file, but on stderr as well as to OIIO; a cut-off download is the
// commonest broken texture, so it is caught here, quietly.
bool pngChunksComplete(const unsigned char* bytes, size_t size) {
    size_t at = 8;
    while (at + 12 <= size) {
        const uint64_t length = (uint64_t(bytes[at]) << 24) | (uint64_t(bytes[at + 1]) << 16) |
                                (uint64_t(bytes[at + 2]) << 8) | uint64_t(bytes[at + 3]);
        if (length > size - at - 12) return false;
        if (std::memcmp(bytes + at + 4, "IEND", 4) == 0) return true;
        at += 12 + size_t(length);
    }
    return false;
}

// OIIO's messages may span lines; a warning is one.
std::string oneLine(std::string text) {
    for (char& c : text)
        if (c == '\n') c = ' ';
    while (!text.empty() && text.back() == ' ') text.pop_back();
    return text;
}

}  // namespace

TextureColour meanTextureColour(const unsigned char* bytes, size_t size) {
    TextureColour out;
    const char* extension = extensionOf(bytes, size);
    if (!extension) {
        out.problem = "is neither PNG nor JPEG (the image formats glTF 2.0 allows)";
        return out;
    }
    if (std::strcmp(extension, "png") == 0 && !pngChunksComplete(bytes, size)) {
        out.problem = "is a truncated PNG (its chunks end before IEND)";
        return out;
    }
    OIIO::Filesystem::IOMemReader memory(bytes, size);
    auto input = OIIO::ImageInput::create(extension);
    if (!input || !input->supports("ioproxy") || !input->set_ioproxy(&memory)) {
        out.problem = std::string("cannot be decoded: this OpenImageIO cannot read ") + extension + " from memory";
        return out;
    }
    // Colour as stored: OIIO would otherwise multiply it by alpha (associate it) on reading.
    OIIO::ImageSpec config, opened;
    config.attribute("oiio:UnassociatedAlpha", 1);
    if (!input->open(std::string("texture.") + extension, opened, config)) {
        out.problem = "cannot be decoded: " + oneLine(input->geterror());
        return out;
    }
    const OIIO::ImageSpec& spec = input->spec();
    const size_t width = size_t(std::max(spec.width, 0)), height = size_t(std::max(spec.height, 0));
    const int channels = spec.nchannels;
    if (width == 0 || height == 0 || channels <= 0 || spec.depth > 1) {
        out.problem = "has no pixels";
        return out;
    }
    if (width > kMaxTexturePixels / height) {
        out.problem = "is " + std::to_string(width) + " x " + std::to_string(height) +
                      " pixels, more than qsgi decodes (16384 x 16384); skipped";
        return out;
    }
    // 8-bit images are read as 8 bits and anything deeper as 16, each value through a table of
    // the sRGB curve (one pow per possible value, not per pixel).
    const bool sixteen = spec.format.size() > 1;
    const OIIO::TypeDesc readAs = sixteen ? OIIO::TypeDesc::UINT16 : OIIO::TypeDesc::UINT8;
    const size_t levels = sixteen ? 65536 : 256;
    std::vector<double> linear(levels);
    for (size_t v = 0; v < levels; ++v) linear[v] = srgbToLinear(double(v) / double(levels - 1));

    std::vector<uint16_t> row16(sixteen ? width * size_t(channels) : 0);
    std::vector<uint8_t> row8(sixteen ? 0 : width * size_t(channels));
    double sum[3] = {0, 0, 0};
    for (int y = spec.y; y < spec.y + spec.height; ++y) {
        void* row = sixteen ? static_cast<void*>(row16.data()) : static_cast<void*>(row8.data());
        if (!input->read_scanline(y, spec.z, readAs, row)) {
            out.problem = "is truncated or corrupt: " + oneLine(input->geterror());
            return out;
        }
        for (size_t x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                const size_t at = x * size_t(channels) + size_t(channels >= 3 ? c : 0);  // grey: one channel
                sum[c] += linear[sixteen ? row16[at] : row8[at]];
            }
    }
    const double pixels = double(width) * double(height);
    out.mean = Vec3f(float(sum[0] / pixels), float(sum[1] / pixels), float(sum[2] / pixels));
    return out;
}

}  // namespace qsgi
