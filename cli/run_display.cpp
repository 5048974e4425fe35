#include "run_display.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace {

double median(std::vector<double> values) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

std::string RunDisplay::status(int index, int count) const {
    std::string text = "qsgi: frame " + std::to_string(index + 1) + "/" + std::to_string(count) + "  " +
                       qsgi::formatDuration(clock_.seconds()) + " elapsed";
    // What remains: the frames after the first are updates and cost alike, the first (from
    // scratch) more; so the median of the updates so far, or the first frame's time until then.
    if (!frameSeconds_.empty()) {
        const std::vector<double> updates(frameSeconds_.begin() + (frameSeconds_.size() > 1 ? 1 : 0), frameSeconds_.end());
        const double perFrame = median(updates);
        text += ", ~" + qsgi::formatDuration(perFrame * double(count - index)) + " left";
    }
    return text;
}

void RunDisplay::stage(const qsgi::StageReport& r) {
    std::string text = status(r.index, r.count) + "  " + r.stage;
    if (r.total) text += " " + qsgi::progressBar(r.done, r.total);
    // A new stage is always drawn; the tracing bar's updates at most ten times a second.
    line_.show(text, r.done == 0);
}

void RunDisplay::frameDone(const qsgi::FrameReport& r) {
    frameSeconds_.push_back(r.seconds);
    if (r.index + 1 < r.count) line_.show(status(r.index + 1, r.count), true);
}

std::string RunDisplay::summary(const std::string& outDir) const {
    const size_t n = frameSeconds_.size();
    char text[512];
    std::snprintf(text, sizeof text, "wrote %zu frame%s to %s in %s (median frame %.2f s", n, n == 1 ? "" : "s",
                  outDir.c_str(), qsgi::formatDuration(clock_.seconds()).c_str(), median(frameSeconds_));
    std::string line = text;
    if (n > 1) {
        std::snprintf(text, sizeof text, "; first %.2f s, from scratch", frameSeconds_.front());
        line += text;
    }
    return line + ")";
}
