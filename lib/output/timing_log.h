// timing.json (docs/design.md §7): the run's configuration, per-frame timings and work counts, and the
// summaries that mirror the paper's table (initial frame vs. per-frame update).
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "util/frame_timing.h"

namespace qsgi {

struct TimingLog {
    // "config": the options the option table marks for the log (optionValues), by config key;
    // null where an option means nothing for the run. "threads" is the count the run used.
    nlohmann::json config = nlohmann::json::object();
    uint64_t photons = 0;              // traced per frame
    uint64_t photonsMissingScene = 0;  // at the run's first frame
    double emittedFraction = 1;        // LightSampler::emittedFraction
    bool emissionMeasured = false;     // the two above are set (after this run's first frame)
    // scene
    std::string scene;
    uint64_t vertices = 0, triangles = 0, dynamicVertices = 0, lights = 0;
    uint64_t degenerateTriangles = 0;
    uint64_t inputVertices = 0;  // before --subdivide and --refine-contacts
    uint64_t backSideVertices = 0;  // the back sides of doubleSided surfaces (lib/scene/back_sides.h)
    // --refine-contacts: the vertices it added and the frames whose poses it judged (null without it).
    nlohmann::json contactRefinement;
    // --vertex-fit least-squares: the sampling mesh's vertices, which the frames are solved on (0 without it).
    uint64_t fitSamples = 0;
    double animationDiagonal = 0;  // the diagonal of the whole animation's bounds (default radius = 1.5 % of it)
    // runFingerprint of the inputs and settings; --resume continues only a folder whose log has it.
    std::string inputsFingerprint;
    // Set-up outside the frames (issue 58), from the run's first frame: the seconds from the
    // job's start to its first frame, aimed emission's maps and probes, the direct light's tree.
    nlohmann::json setup;
    // What the fingerprint is made of ("inputs": RunFingerprint::parts), for naming what differs.
    nlohmann::json inputs;

    std::vector<FrameTiming> frames;  // in the order they were written (timing.json lists them by frame)

    // The file's text (OutputDirectory::write puts it on disk).
    std::string text() const;
};

// What --resume needs from an earlier run's timing.json: its fingerprint, what it is made of (null
// in a log of an older qsgi) and its frames. Throws InputError naming the file if it is not a
// timing log qsgi wrote.
struct EarlierRun {
    std::string inputsFingerprint;
    nlohmann::json inputs;
    std::vector<FrameTiming> frames;  // with the files each records (none in an older qsgi's log)
};
EarlierRun readTimingLog(const std::filesystem::path& path);

}  // namespace qsgi
