// One knob for speed against accuracy (--quality LEVEL, issue 60 item 4): named sets of the options
// that trade time for noise — photons traced, final-gather rays and shadow rays per vertex — each a
// point measured on the error-against-time front of the committed scenes (data/cornell and
// tests/scenes/ceiling_panel against their independent references; the table and the front in
// docs/photons-and-radius.md, "One knob: --quality"). "standard" is the defaults. An option given on
// its own (--photons, --gather, --direct-samples, or their config keys) overrides its level's value,
// wherever either is given.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>

namespace qsgi {

struct QualityLevel {
    const char* name;
    uint64_t photons;
    uint32_t gatherRays;
    uint32_t directSamples;
};

// Fastest first. Measured (frame 0, 2 cores, vertex error against the independent reference,
// whose own noise is about 1 %): on data/cornell draft 2.5 % in 0.41 s, fast 1.6 % in 1.1 s,
// standard 1.4 % in 2.0 s, high 1.4 % in 4.0 s; on the ceiling panel 2.5, 1.5, 1.5 and 1.4 % in
// 0.19, 0.52, 1.0 and 1.7 s. Tripling the photons past high bought 0.07 % more on data/cornell
// for 1.8 s more, and nothing on the panel: not a level.
inline constexpr QualityLevel kQualityLevels[] = {
    {"draft", 100000, 64, 16},
    {"fast", 300000, 256, 64},
    {"standard", 1000000, 256, 64},
    {"high", 1000000, 1024, 64},
};
inline constexpr const char* kDefaultQuality = "standard";

// The level of that name (the option's choices are these names: an unknown one is a caller's error).
inline const QualityLevel& qualityLevel(const std::string& name) {
    for (const QualityLevel& level : kQualityLevels)
        if (name == level.name) return level;
    throw std::logic_error("no quality level '" + name + "'");
}

}  // namespace qsgi
