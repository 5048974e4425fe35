#include "output/image_compare.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/imagebufalgo.h>

#include "util/error.h"
#include "util/input_file.h"

namespace qsgi {

namespace {

// The first subimage of the image file at `path` as floats, decoded from the bytes read from the
// descriptor the opening rule checked (util/input_file.h): the file is opened once, OpenImageIO
// never opens the path. Empty with `problem` set if it cannot be read.
OIIO::ImageBuf readImage(const std::filesystem::path& path, std::string& problem) {
    try {
        InputFile file(path.string(), kMaxImageFileBytes, "an image");
        const std::string bytes = file.readAll();
        OIIO::Filesystem::IOMemReader memory(bytes.data(), bytes.size());
        auto input = OIIO::ImageInput::open(path.string(), nullptr, &memory);
        if (!input) {
            problem = path.string() + ": " + OIIO::geterror();
            return {};
        }
        if (!input->supports("ioproxy")) {
            problem = path.string() + ": OpenImageIO reads the '" + std::string(input->format_name()) +
                      "' format only by opening the path again";
            return {};
        }
        OIIO::ImageSpec spec = input->spec();
        spec.set_format(OIIO::TypeDesc::FLOAT);
        OIIO::ImageBuf image(spec);
        if (!input->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, image.localpixels())) {
            problem = path.string() + ": " + input->geterror();
            return {};
        }
        return image;
    } catch (const InputError& e) {
        problem = e.what();
        return {};
    }
}

}  // namespace

ImageComparison compareImages(const std::filesystem::path& candidate, const std::filesystem::path& reference,
                              const ImageTolerance& tolerance, const std::filesystem::path& differencePath) {
    ImageComparison out;
    std::string problem;
    const OIIO::ImageBuf a = readImage(candidate, problem);
    const OIIO::ImageBuf b = problem.empty() ? readImage(reference, problem) : OIIO::ImageBuf();
    if (!problem.empty()) {
        out.problem = "cannot read: " + problem;
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
