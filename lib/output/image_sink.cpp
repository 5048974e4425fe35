#include "output/image_sink.h"

#include "util/stopwatch.h"

namespace qsgi {

RgbImage ImageSink::render(const SolvedFrame& frame) const {
    return renderRadiosityImage(frame.scene, frame.bvh, frame.result, settings_.cameraAt(frame.frame), settings_.image);
}

void ImageSink::calibrate(const SolvedFrame& frame0) {
    if (settings_.png && !exposure_) exposure_ = automaticExposure(render(frame0));
}

double ImageSink::prepare(const SolvedFrame& frame) {
    Stopwatch clock;
    image_ = render(frame);
    return clock.seconds();
}

void ImageSink::encode(const SolvedFrame& frame, std::vector<EncodedFile>& files) {
    if (settings_.exr) files.push_back({"exr", encodeExr(image_, settings_.metadataAt(frame.frame), settings_.exrHalf)});
    if (settings_.png) files.push_back({"png", encodePngPreview(image_, *exposure_)});
}

}  // namespace qsgi
