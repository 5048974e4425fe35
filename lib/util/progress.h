// A status line on stderr for long runs (issue 22): redrawn in place on a terminal, at most ten
// times a second, and cleared before anything else is printed. A disabled line prints nothing, so
// callers need not check whether stderr is a terminal.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace qsgi {

class ProgressLine {
public:
    explicit ProgressLine(bool enabled) : enabled_(enabled) {}
    ~ProgressLine() { clear(); }
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    // Shows `text` in place of the previous line; thread-safe. Skipped when the last drawing was
    // under 0.1 s ago, unless `force` (a new frame or stage is always drawn).
    void show(const std::string& text, bool force = false);
    // Erases the line (before other output, and at the end).
    void clear();

private:
    bool enabled_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point last_{};
    std::mutex mutex_;
};

// "[########            ]  41%": done of total in `width` cells.
std::string progressBar(uint64_t done, uint64_t total, int width = 20);
// "0:07", "12:34", "1:02:03" (rounded to the second).
std::string formatDuration(double seconds);

// True when stderr is an interactive terminal.
bool stderrIsTerminal();

}  // namespace qsgi
