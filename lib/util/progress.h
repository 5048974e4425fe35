// A progress bar on stderr for long work (DESIGN §8). Disabled bars print nothing, so callers
// need not check whether stderr is a terminal.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>

namespace qsgi {

class ProgressBar {
public:
    ProgressBar(std::string title, uint64_t total, bool enabled);
    ~ProgressBar();
    void update(uint64_t done);  // thread-safe
    void finish();

private:
    std::string title_;
    uint64_t total_;
    bool enabled_;
    bool finished_ = false;
    int lastPermille_ = -1;
    std::mutex mutex_;
};

// True when stderr is an interactive terminal.
bool stderrIsTerminal();

}  // namespace qsgi
