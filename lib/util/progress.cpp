#include "util/progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace qsgi {

bool stderrIsTerminal() { return isatty(STDERR_FILENO) == 1; }

void ProgressLine::show(const std::string& text, bool force) {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (!force && drawn_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    drawn_ = true;
    // Clipped to the terminal's width: a line that wraps is not redrawn in place but leaves a
    // stray line at every redraw.
    std::string shown = text;
    winsize size{};
    if (ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 1 && shown.size() >= size.ws_col)
        shown.resize(size_t(size.ws_col) - 1);
    // Carriage return, the text, then erase whatever a longer previous line left.
    std::fprintf(stderr, "\r%s\033[K", shown.c_str());
    std::fflush(stderr);
}

void ProgressLine::clear() {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!drawn_) return;
    drawn_ = false;
    std::fprintf(stderr, "\r\033[K");
    std::fflush(stderr);
}

std::string progressBar(uint64_t done, uint64_t total, int width) {
    const double fraction = total ? std::min(1.0, double(done) / double(total)) : 0.0;
    const int filled = int(fraction * width);
    char percent[16];
    std::snprintf(percent, sizeof percent, "] %3d%%", int(fraction * 100));
    return "[" + std::string(size_t(filled), '#') + std::string(size_t(width - filled), ' ') + percent;
}

std::string formatDuration(double seconds) {
    const long total = std::isfinite(seconds) && seconds > 0 ? long(std::lround(seconds)) : 0;
    char text[32];
    if (total >= 3600) std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", total / 3600, total / 60 % 60, total % 60);
    else std::snprintf(text, sizeof text, "%ld:%02ld", total / 60, total % 60);
    return text;
}

}  // namespace qsgi
