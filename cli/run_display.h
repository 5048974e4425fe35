// What `qsgi render` shows while it runs (issue 22): on a terminal, one status line redrawn in
// place — frame i of N, elapsed time, an estimate of what remains, and the current frame's stage
// with a bar while photons are traced; and, unless --quiet, one summary line at the end whether
// or not stderr is a terminal.
#pragma once

#include <string>
#include <vector>

#include "pipeline/render_job.h"
#include "util/progress.h"
#include "util/stopwatch.h"

class RunDisplay {
public:
    // live: draw the status line (stderr is a terminal and not --quiet).
    explicit RunDisplay(bool live) : line_(live) {}

    void stage(const qsgi::StageReport& report);  // from any thread
    void frameDone(const qsgi::FrameReport& report);
    // Erases the status line, so that a message can be printed on a clean line.
    void clearLine() { line_.clear(); }
    // "wrote 60 frames to out/cornell in 1:34 (median frame 1.21 s; first 4.02 s)".
    std::string summary(const std::string& outDir) const;

private:
    std::string status(int index, int count) const;

    qsgi::ProgressLine line_;
    qsgi::Stopwatch clock_;
    std::vector<double> frameSeconds_;  // of this run's frames, in order
};
