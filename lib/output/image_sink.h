// frame_NNNN.exr and frame_NNNN.png (docs/outputs.md): the camera's view of the solution, rendered
// once a frame for both. The PNG's automatic exposure is animation frame 0's.
#pragma once

#include <functional>
#include <optional>

#include "output/frame_sink.h"
#include "output/image_files.h"
#include "output/radiosity_image.h"

namespace qsgi {

struct ImageSinkSettings {
    bool exr = true, exrHalf = false, png = false;
    std::optional<float> exposure;  // the PNG's; unset: automatic, from frame 0
    ImageSettings image;
    std::function<Camera(int)> cameraAt;            // the view at a frame
    std::function<ImageMetadata(int)> metadataAt;   // the EXR's header at a frame
};

class ImageSink : public FrameSink {
public:
    explicit ImageSink(ImageSinkSettings settings) : settings_(std::move(settings)), exposure_(settings_.exposure) {}
    void calibrate(const SolvedFrame& frame0) override;
    const char* preparingStage() const override { return "image"; }
    double prepare(const SolvedFrame& frame) override;
    void encode(const SolvedFrame& frame, std::vector<EncodedFile>& files) override;

private:
    RgbImage render(const SolvedFrame& frame) const;

    ImageSinkSettings settings_;
    std::optional<float> exposure_;
    RgbImage image_;  // the frame prepared
};

}  // namespace qsgi
