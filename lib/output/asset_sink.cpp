#include "output/asset_sink.h"

#include <cmath>
#include <optional>

#include "output/output_directory.h"
#include "output/ply_reader.h"
#include "output/ply_writer.h"
#include "util/stopwatch.h"

namespace qsgi {

void AssetSink::finish(OutputDirectory& out, WholeRunReport& report) {
    Warnings warnings;
    const double fps = settings_.fps;
    std::optional<BakedFrame> firstFrame;  // read once: for the exposure here and by the encoder
    auto frameAt = [&](size_t k) {
        if (k == 0 && firstFrame) return *firstFrame;
        const int frame = settings_.first + int(k);
        const std::string path = (out.path() / settings_.plyName(frame)).string();
        const VertexRadiosityPly ply = readVertexRadiosityPly(path);
        if (ply.radiosity.size() != scene_.vertexCount() || ply.irradiance.size() != scene_.vertexCount())
            throw InputError(path, "",
                             ply.irradiance.empty() ? "has no irradiance (an older qsgi wrote it): render it again without --resume"
                                                    : "does not hold this scene's vertices");
        BakedFrame baked;
        baked.seconds = fps > 0 ? frame / fps : 0;
        baked.radiance.resize(ply.radiosity.size());
        for (size_t v = 0; v < ply.radiosity.size(); ++v) baked.radiance[v] = ply.radiosity[v] * float(1 / M_PI);
        baked.irradiance = ply.irradiance;
        return baked;
    };
    BakedAssetSettings asset = settings_.asset;
    // COLOR_n's exposure puts the first frame's 99th percentile of B/π at 1, as the PLY previews
    // do with frame 0's.
    firstFrame = frameAt(0);
    asset.exposure = double(PreviewTonemap::fromPercentile(firstFrame->radiance).scale);
    Stopwatch clock;
    BakedAssetSummary summary;
    const std::string bytes = encodeBakedAsset(*settings_.document, scene_, size_t(settings_.last - settings_.first + 1), frameAt,
                                               settings_.motion, asset, warnings, &summary);
    out.write(kBakedAssetName, bytes);
    report.bytes = summary.bytes;
    report.bakeBytes = summary.bakeBytes;
    report.seconds = clock.seconds();
    report.warnings = warnings.messages;
}

}  // namespace qsgi
