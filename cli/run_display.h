// What `qsgi render` shows while it runs (issue 22): on a terminal, one status line redrawn in
// place — frame i of N, elapsed time, an estimate of what remains, and the current frame's stage
// with a bar where its work is counted (tracing, disc regions, estimation) — and, unless --quiet,
// one summary line at the end whether or not stderr is a terminal. A ticker thread redraws the
// line a few times a second, so the clock moves through stages that report nothing for a while.
#pragma once

#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/render_job.h"
#include "util/progress.h"
#include "util/stopwatch.h"

class RunDisplay {
public:
    // live: draw the status line (stderr is a terminal and not --quiet).
    explicit RunDisplay(bool live);
    ~RunDisplay();
    RunDisplay(const RunDisplay&) = delete;
    RunDisplay& operator=(const RunDisplay&) = delete;

    void stage(const qsgi::StageReport& report);  // from any thread
    void frameDone(const qsgi::FrameReport& report);
    // Prints one line of text on stderr in place of the status line (redrawn at the next tick).
    void message(const std::string& text);
    // Erases the status line for good: the run is over.
    void finish();
    // "wrote 60 frames to out/cornell in 1:34 (median frame 1.21 s; first 4.02 s, from scratch)",
    // and the frames of the same run the folder already held.
    std::string summary(const std::string& outDir, const qsgi::RunOutcome& outcome) const;

private:
    // The line for the frame at `index` of `count` and the stage in progress; mutex_ held.
    std::string status(int index, int count) const;
    void draw(bool force);  // mutex_ held
    void tick();

    qsgi::ProgressLine line_;
    qsgi::Stopwatch clock_, frameClock_;
    mutable std::mutex mutex_;
    std::vector<double> frameSeconds_;  // of this run's frames, in order
    qsgi::StageReport current_{0, 0, 0, nullptr, 0, 0};  // stage nullptr: between frames
    int nextIndex_ = 0, count_ = 0;                       // for the line between frames
    bool stopping_ = false;
    std::condition_variable wake_;
    std::thread ticker_;
};
