#include "util/progress.h"

#include <unistd.h>

#include <cstdio>

namespace qsgi {

bool stderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

ProgressBar::ProgressBar(std::string title, uint64_t total, bool enabled)
    : title_(std::move(title)), total_(total ? total : 1), enabled_(enabled) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(uint64_t done) {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    const int permille = int(std::min<uint64_t>(done, total_) * 1000 / total_);
    if (permille == lastPermille_) return;
    lastPermille_ = permille;
    constexpr int kWidth = 40;
    const int filled = permille * kWidth / 1000;
    std::fprintf(stderr, "\r%s [%.*s%*s] %5.1f%%", title_.c_str(), filled, "########################################",
                 kWidth - filled, "", permille / 10.0);
    std::fflush(stderr);
}

void ProgressBar::finish() {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    finished_ = true;
    std::fprintf(stderr, "\n");
}

}  // namespace qsgi
