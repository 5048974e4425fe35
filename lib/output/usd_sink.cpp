#include "output/usd_sink.h"

#include <algorithm>
#include <cstdio>

#include "output/folder_survey.h"
#include "output/frame_readback.h"
#include "output/output_directory.h"
#include "util/stopwatch.h"

namespace qsgi {

WholeRunReport UsdSink::make(OutputDirectory& out) {
    WholeRunReport report;
    Stopwatch clock;
    UsdAssetSummary summary;
    auto frameAt = [&](int frame) { return readFramePly(out, frame, scene_); };
    out.writeStreamed(kUsdAssetName, [&](const OutputDirectory::PieceWriter& put) {
        writeUsdAsset(scene_, settings_, frameAt, put, &summary);
    });
    report.name = kUsdAssetName;
    report.bytes = summary.bytes;
    char sizes[96];
    std::snprintf(sizes, sizeof sizes, "%.1f MB, %.0f bytes a vertex-frame", double(summary.bytes) * 1e-6,
                  double(summary.bytes) / double(std::max<size_t>(1, summary.points * summary.frames)));
    report.sizes = sizes;
    report.seconds = clock.seconds();
    return report;
}

}  // namespace qsgi
