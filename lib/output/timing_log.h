// timing.json (DESIGN §7): the run's configuration, per-frame timings and work counts, and the
// summaries that mirror the paper's table (initial frame vs. per-frame update).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "util/frame_timing.h"

namespace qsgi {

struct TimingLog {
    // config
    std::string estimator;
    float radius = 0;
    int k = 0;
    bool rayCache = true, sortQueries = true;
    std::string detpIndex;
    std::string boundary;  // DETP / photon-map boundary rule
    uint64_t photons = 0, seed = 0;
    int threads = 0;
    bool fullRecompute = false;
    bool envelope = true;
    bool aimEmission = true;
    std::string sampler;
    uint32_t qmcBounces = 0;  // written only under sobol
    uint64_t photonsMissingScene = 0;  // at the run's first frame
    double emittedFraction = 1;        // LightSampler::emittedFraction
    bool emissionMeasured = false;     // the two above are set (after this run's first frame)
    // scene
    std::string scene;
    uint64_t vertices = 0, triangles = 0, dynamicVertices = 0, lights = 0;
    uint64_t degenerateTriangles = 0;
    double animationDiagonal = 0;  // the diagonal of the whole animation's bounds (default radius = 1.5 % of it)
    // runFingerprint of the inputs and settings; --resume continues only a folder whose log has it.
    std::string inputsFingerprint;

    std::vector<FrameTiming> frames;  // in the order they were written

    void write(const std::filesystem::path& path) const;  // atomically
};

// What --resume needs from an earlier run's timing.json: its fingerprint and its frames. Throws
// InputError naming the file if it is not a timing log qsgi wrote.
struct EarlierRun {
    std::string inputsFingerprint;
    std::vector<FrameTiming> frames;
};
EarlierRun readTimingLog(const std::filesystem::path& path);

}  // namespace qsgi
