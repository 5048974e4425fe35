#include "run_display.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>

namespace {

double median(std::vector<double> values) {
    if (values.empty()) return 0;
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// How often the ticker redraws: the elapsed time, in whole seconds, then never lags by more.
constexpr auto kTick = std::chrono::milliseconds(250);

}  // namespace

RunDisplay::RunDisplay(bool live) : line_(live) {
    if (live) ticker_ = std::thread([this] { tick(); });
}

RunDisplay::~RunDisplay() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    if (ticker_.joinable()) ticker_.join();
}

void RunDisplay::tick() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (!wake_.wait_for(lock, kTick, [this] { return stopping_; })) draw(true);
}

std::string RunDisplay::status(int index, int count) const {
    std::string text = "qsgi: frame " + std::to_string(index + 1) + "/" + std::to_string(count) + "  " +
                       qsgi::formatDuration(clock_.seconds()) + " elapsed";
    // What remains: the frames after the first are updates and cost alike, the first (from
    // scratch) more; so the median of the updates so far (or the first frame's time until then)
    // for each frame not done, less what the current one has already taken.
    if (!frameSeconds_.empty()) {
        const std::vector<double> updates(frameSeconds_.begin() + (frameSeconds_.size() > 1 ? 1 : 0), frameSeconds_.end());
        const double perFrame = median(updates);
        const double left = perFrame * double(count - index - 1) + std::max(perFrame - frameClock_.seconds(), 0.0);
        text += ", ~" + qsgi::formatDuration(left) + " left";
    }
    return text;
}

void RunDisplay::draw(bool force) {
    if (count_ == 0) return;  // nothing has started
    std::string text;
    if (current_.stage) {
        text = status(current_.index, current_.count) + "  " + current_.stage;
        if (current_.total) text += " " + qsgi::progressBar(current_.done, current_.total);
    } else {
        text = status(nextIndex_, count_);
    }
    line_.show(text, force);
}

void RunDisplay::stage(const qsgi::StageReport& r) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool newStage = !current_.stage || std::strcmp(current_.stage, r.stage) != 0 || r.done == 0;
    current_ = r;
    count_ = r.count;
    // A new stage is always drawn; a bar's updates at most ten times a second.
    draw(newStage);
}

void RunDisplay::frameDone(const qsgi::FrameReport& r) {
    std::lock_guard<std::mutex> lock(mutex_);
    frameSeconds_.push_back(r.seconds);
    frameClock_.restart();
    current_.stage = nullptr;
    nextIndex_ = r.index + 1;
    count_ = r.count;
    if (r.index + 1 < r.count) draw(true);
    else count_ = 0;  // the run is over: nothing more to draw
}

void RunDisplay::message(const std::string& text) {
    std::lock_guard<std::mutex> lock(mutex_);
    line_.clear();
    std::fprintf(stderr, "%s\n", text.c_str());
}

void RunDisplay::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    count_ = 0;
    line_.clear();
}

std::string RunDisplay::summary(const std::string& outDir, const qsgi::RunOutcome& outcome) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const size_t n = frameSeconds_.size();
    char text[512];
    std::snprintf(text, sizeof text, "wrote %zu frame%s to %s in %s (median frame %.2f s", n, n == 1 ? "" : "s",
                  outDir.c_str(), qsgi::formatDuration(clock_.seconds()).c_str(), median(frameSeconds_));
    std::string line = text;
    if (n > 1) {
        std::snprintf(text, sizeof text, "; first %.2f s, from scratch", frameSeconds_.front());
        line += text;
    }
    line += ")";
    const int kept = outcome.framesKept + outcome.framesResumed;
    if (kept > 0)
        line += "; the folder also holds " + std::to_string(kept) + " earlier frame" + (kept == 1 ? "" : "s") +
                " of the same run, listed in its timing.json";
    return line;
}
