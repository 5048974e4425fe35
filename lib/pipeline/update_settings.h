// How frames after the first are solved (docs/design.md §6): updated from the previous frame, or
// from scratch, and the switches that measure the update's parts against their baselines. Every
// choice gives the same bytes. A light header: the option table sets these fields directly.
#pragma once

#include <cstdint>

namespace qsgi {

// The most retraces of one path before every tracked path is renumbered (TrackedPaths::kGenerations;
// frame_solver.h checks they agree).
constexpr uint32_t kTrackedGenerations = 256;  // a tracked record's generation is one byte

struct UpdateSettings {
    bool fullRecompute = false;   // every frame from scratch
    bool alwaysUpdate = false;    // never fall back to scratch for a large change (tests, measurements)
    bool useEnvelope = true;      // false: track every path (for tests and the memory comparison)
    bool gridForBlocking = true;  // false: test every tracked segment for blocking (benchmark baseline)
    // Retraces of one path before every tracked path is renumbered (TrackedPaths; tests lower it,
    // no option sets it).
    uint32_t trackedGenerations = kTrackedGenerations;
};

}  // namespace qsgi
