#include "output/asset_sink.h"

#include <cstdio>
#include <optional>

#include "output/output_directory.h"
#include "output/folder_survey.h"
#include "output/frame_readback.h"
#include "output/ply_writer.h"
#include "util/stopwatch.h"

namespace qsgi {

WholeRunReport AssetSink::make(OutputDirectory& out) {
    WholeRunReport report;
    Warnings warnings;
    const double fps = settings_.fps;
    std::optional<BakedFrame> firstFrame;  // read once: for the exposure here and by the encoder
    auto frameAt = [&](size_t k) {
        if (k == 0 && firstFrame) return *firstFrame;
        const int frame = settings_.first + int(k);
        VertexRadiosityPly ply = readFramePly(out, frame, scene_);
        BakedFrame baked;
        baked.seconds = fps > 0 ? frame / fps : 0;
        baked.radiance.resize(ply.radiosity.size());
        for (size_t v = 0; v < ply.radiosity.size(); ++v) baked.radiance[v] = bakedRadiance(ply.radiosity[v]);
        baked.irradiance = std::move(ply.irradiance);
        baked.backRadiance.resize(ply.backRadiosity.size());
        for (size_t v = 0; v < ply.backRadiosity.size(); ++v) baked.backRadiance[v] = bakedRadiance(ply.backRadiosity[v]);
        baked.backIrradiance = std::move(ply.backIrradiance);
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
    report.name = kBakedAssetName;
    report.bytes = summary.bytes;
    char sizes[96];
    std::snprintf(sizes, sizeof sizes, "%.1f MB, of which the bake %.1f MB", double(summary.bytes) * 1e-6, double(summary.bakeBytes) * 1e-6);
    report.sizes = sizes;
    report.seconds = clock.seconds();
    report.warnings = warnings.messages;
    return report;
}

}  // namespace qsgi
