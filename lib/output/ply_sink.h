// frame_NNNN.ply (docs/outputs.md): every vertex's radiosity and irradiance, with a preview colour
// tonemapped as animation frame 0 is.
#pragma once

#include <optional>

#include "output/frame_sink.h"
#include "output/ply_writer.h"

namespace qsgi {

class PlySink : public FrameSink {
public:
    void calibrate(const SolvedFrame& frame0) override { tonemap_ = PreviewTonemap::fromPercentile(frame0.result.radiosity); }
    void encode(const SolvedFrame& frame, std::vector<EncodedFile>& files) override {
        files.push_back({"ply", encodeVertexRadiosityPly(frame.scene, frame.result, *tonemap_)});
    }

private:
    std::optional<PreviewTonemap> tonemap_;
};

}  // namespace qsgi
