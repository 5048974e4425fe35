#include "output/image_files.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "output/srgb.h"

namespace qsgi {

namespace {
// `format` is a file name whose extension picks OpenImageIO's writer; nothing is opened by it.
std::string encodeWithOiio(const char* format, const OIIO::ImageSpec& spec, OIIO::TypeDesc pixelType, const void* pixels) {
    std::vector<unsigned char> bytes;
    OIIO::Filesystem::IOVecOutput memory(bytes);
    auto out = OIIO::ImageOutput::create(format, &memory);
    if (!out || !out->supports("ioproxy"))
        throw std::runtime_error(std::string("OpenImageIO cannot encode ") + format + " in memory: " + OIIO::geterror());
    if (!out->set_ioproxy(&memory) || !out->open(format, spec) || !out->write_image(pixelType, pixels) || !out->close())
        throw std::runtime_error(std::string("encoding ") + format + " failed: " + out->geterror());
    return std::string(bytes.begin(), bytes.end());
}
}  // namespace

std::string encodeExr(const RgbImage& image, const ImageMetadata& metadata, bool half) {
    OIIO::ImageSpec spec(image.width, image.height, 3, half ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::FLOAT);
    spec.attribute("compression", "zip");
    // OpenImageIO stamps the wall-clock time unless told otherwise; a fixed stamp keeps the same
    // inputs giving the same bytes (golden images, caches, diffs).
    spec.attribute("DateTime", "1970:01:01 00:00:00");
    for (const auto& [k, v] : metadata.strings) spec.attribute(k, v);
    for (const auto& [k, v] : metadata.ints) spec.attribute(k, v);
    for (const auto& [k, v] : metadata.floats) spec.attribute(k, v);
    return encodeWithOiio("frame.exr", spec, OIIO::TypeDesc::FLOAT, image.pixels.data());
}

float automaticExposure(const RgbImage& image, double percentile) {
    std::vector<float> lum;
    for (size_t i = 0; i + 2 < image.pixels.size(); i += 3) {
        const float l = luminance(Vec3f(image.pixels[i], image.pixels[i + 1], image.pixels[i + 2]));
        if (l > 0 && std::isfinite(l)) lum.push_back(l);
    }
    if (lum.empty()) return 1.0f;
    const size_t k = std::min(lum.size() - 1, size_t(percentile * double(lum.size())));
    std::nth_element(lum.begin(), lum.begin() + k, lum.end());
    return 0.8f / lum[k];
}

std::string encodePngPreview(const RgbImage& image, float exposure) {
    std::vector<uint8_t> bytes(image.pixels.size());
    for (size_t i = 0; i < bytes.size(); ++i) {
        bytes[i] = encodeSrgb8(image.pixels[i] * exposure);
    }
    OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::UINT8);
    return encodeWithOiio("frame.png", spec, OIIO::TypeDesc::UINT8, bytes.data());
}

}  // namespace qsgi
