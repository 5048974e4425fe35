// Writing renders: linear EXR through OpenImageIO with the run's metadata, and an 8-bit sRGB PNG
// preview. Both atomically (temporary file in the same folder, then rename).
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "output/radiosity_image.h"

namespace qsgi {

struct ImageMetadata {
    std::vector<std::pair<std::string, std::string>> strings;
    std::vector<std::pair<std::string, int>> ints;
    std::vector<std::pair<std::string, float>> floats;
};

void writeExr(const std::filesystem::path& path, const RgbImage& image, const ImageMetadata& metadata, bool half);

// exposure multiplies the linear radiance before sRGB encoding and clamping.
void writePngPreview(const std::filesystem::path& path, const RgbImage& image, float exposure);

// Exposure that maps the given percentile of the pixels' luminance (background excluded) to 0.8.
float automaticExposure(const RgbImage& image, double percentile = 0.99);

}  // namespace qsgi
