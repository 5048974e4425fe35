// Golden-image comparison as CI pipelines do it, through OpenImageIO's ImageBufAlgo::compare
// (the numbers idiff prints), with thresholds relative to the reference's brightness.
#pragma once

#include <filesystem>
#include <string>

namespace qsgi {

struct ImageTolerance {
    // Fail when mean |A−B| exceeds this fraction of the reference's mean value …
    double maxMeanRelativeError = 2e-3;
    // … or when more than this fraction of pixels has a channel off by more than
    // pixelRelativeThreshold of the two values' mean (and by more than pixelAbsoluteFloor).
    double maxFailingPixelFraction = 0.01;
    float pixelRelativeThreshold = 0.05f;
    float pixelAbsoluteFloor = 1e-4f;
};

struct ImageComparison {
    bool readable = false;   // both images could be read and have the same size and channels
    std::string problem;     // why not, if not
    double meanRelativeError = 0;
    double failingPixelFraction = 0;
    double maxError = 0;
    bool passes(const ImageTolerance& t) const {
        return readable && meanRelativeError <= t.maxMeanRelativeError && failingPixelFraction <= t.maxFailingPixelFraction;
    }
};

// Compares `candidate` with `reference`. If differencePath is not empty, writes |A−B| there.
ImageComparison compareImages(const std::filesystem::path& candidate, const std::filesystem::path& reference,
                              const ImageTolerance& tolerance, const std::filesystem::path& differencePath = {});

}  // namespace qsgi
