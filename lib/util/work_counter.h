// How far a long stage is: work items done of a known total, counted by parallel workers and
// handed to a progress display a few times a second (the status line's bar). Counting costs one
// atomic add per chunk of work; a stage without a counter simply shows no bar.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>

namespace qsgi {

class WorkCounter {
public:
    // Told the stage's name and how far it is; called from the worker threads, one call at a time.
    using Report = std::function<void(const char* stage, uint64_t done, uint64_t total)>;

    explicit WorkCounter(Report report) : report_(std::move(report)) {}

    // A new stage of `total` items (vertices, segments): reported at once as (0, total).
    void start(const char* stage, uint64_t total) {
        std::lock_guard<std::mutex> lock(mutex_);
        stage_ = stage;
        total_ = total;
        done_ = 0;
        lastReport_ = std::chrono::steady_clock::now();
        if (report_) report_(stage_, 0, total_);
    }

    // The stage's size, once whoever does the work knows its unit (vertices, segments).
    void setTotal(uint64_t total) {
        std::lock_guard<std::mutex> lock(mutex_);
        total_ = total;
        done_ = 0;
        if (report_) report_(stage_, 0, total_);
    }

    // The stage's size, corrected once the work is better known (a first total was an upper
    // bound): what is done stands.
    void resize(uint64_t total) {
        std::lock_guard<std::mutex> lock(mutex_);
        total_ = total;
        if (report_) report_(stage_, done_, total_);
    }

    // `n` more items done; reports at most every 100 ms. Thread-safe.
    void add(uint64_t n) {
        const uint64_t done = done_ += n;
        if (!report_) return;
        const auto now = std::chrono::steady_clock::now();
        std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
        // The last item always reports (the bar ends full); the others at most every 100 ms.
        if (done < total_ && (!lock.owns_lock() || now - lastReport_ < std::chrono::milliseconds(100))) return;
        if (!lock.owns_lock()) lock.lock();
        lastReport_ = now;
        report_(stage_, done, total_);
    }

private:
    Report report_;
    std::mutex mutex_;
    const char* stage_ = "";
    uint64_t total_ = 0;
    std::atomic<uint64_t> done_{0};
    std::chrono::steady_clock::time_point lastReport_{};
};

}  // namespace qsgi
