// Encoding renders: linear EXR through OpenImageIO with the run's metadata, and an 8-bit sRGB PNG
// preview. Encoded in memory (an OpenImageIO IOProxy): OpenImageIO opens files by name and would
// follow a link planted in the output folder, so the bytes go to disk through OutputDirectory.
#pragma once

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

// The EXR file's bytes.
std::string encodeExr(const RgbImage& image, const ImageMetadata& metadata, bool half);

// The PNG file's bytes. exposure multiplies the linear radiance before sRGB encoding and clamping.
std::string encodePngPreview(const RgbImage& image, float exposure);

// Exposure that maps the given percentile of the pixels' luminance (background excluded) to 0.8.
float automaticExposure(const RgbImage& image, double percentile = 0.99);

}  // namespace qsgi
