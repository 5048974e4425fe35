#include "output/image_compare.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

namespace qsgi {

ImageComparison compareImages(const std::filesystem::path& candidate, const std::filesystem::path& reference,
                              const ImageTolerance& tolerance, const std::filesystem::path& differencePath) {
    ImageComparison out;
    OIIO::ImageBuf a(candidate.string()), b(reference.string());
    if (!a.read(0, 0, true, OIIO::TypeDesc::FLOAT) || !b.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
        out.problem = "cannot read: " + (a.has_error() ? a.geterror() : b.geterror());
        return out;
    }
    if (a.spec().width != b.spec().width || a.spec().height != b.spec().height || a.nchannels() != b.nchannels()) {
        out.problem = "sizes or channel counts differ";
        return out;
    }
    const OIIO::ImageBufAlgo::CompareResults r = OIIO::ImageBufAlgo::compare(
        a, b, tolerance.pixelAbsoluteFloor, tolerance.pixelAbsoluteFloor, tolerance.pixelRelativeThreshold,
        tolerance.pixelRelativeThreshold);
    // r.error is not checked: OpenImageIO 2.4 also raises it when pixels fail the thresholds,
    // which is a result here, not an error. Reading and size problems were caught above.
    const OIIO::ImageBufAlgo::PixelStats stats = OIIO::ImageBufAlgo::computePixelStats(b);
    double referenceMean = 0;
    for (float m : stats.avg) referenceMean += std::fabs(m);
    referenceMean /= double(std::max<size_t>(stats.avg.size(), 1));
    out.readable = true;
    out.meanRelativeError = referenceMean > 0 ? r.meanerror / referenceMean : r.meanerror;
    out.failingPixelFraction = double(r.nfail) / double(std::max<int64_t>(int64_t(a.spec().width) * a.spec().height, 1));
    out.maxError = r.maxerror;
    if (!differencePath.empty()) {
        OIIO::ImageBuf diff = OIIO::ImageBufAlgo::absdiff(a, b);
        diff.write(differencePath.string());
    }
    return out;
}

}  // namespace qsgi
