// Everything a render run needs to know, from a JSON config (configs/*.json) overridden by the
// command line (docs/design.md §8), and the parsing and range rules the options share. Each option
// is declared once, in render_options.cpp: its key, flag, range, default and help; the config
// reader and validateSettings (render_options.h) and the CLI all apply values through it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "estimate/estimator_settings.h"
#include "estimate/lighting_settings.h"
#include "estimate/vertex_fit_settings.h"
#include "pipeline/quality_level.h"
#include "pipeline/update_settings.h"
#include "scene/scene.h"
#include "trace/trace_settings.h"

namespace qsgi {

struct FrameRange {
    int first = 0;
    int last = -1;  // -1: through the animation's last frame
};

// The stages' own settings (estimator, lighting, trace, update) are held whole: the option table
// sets their fields directly, and RenderJob hands FrameSolver the structs themselves.
struct RenderSettings {
    std::string configPath;     // the config file read, if any (for messages)
    std::string scenePath;
    bool strict = false;  // glTF errors in unused objects refused, not warned (GltfReadOptions)
    std::string animationPath;  // empty: no animation (one frame, 0); "gltf" or "gltf:N": the scene's own
    std::optional<double> fps;  // frames per second at which a glTF animation is sampled (default 24)
    std::string outDir = "out";
    EstimatorSettings estimator;     // radius 0 here: chosen from the scene (defaultRadius)
    bool radiusGiven = false;
    // Exact direct light, 64 samples, 256 gather rays, the gather cache where it pays: the lowest
    // error per second measured (docs/photons-and-radius.md, docs/method.md). LightingSettings'
    // own defaults are the paper's method.
    LightingSettings lighting{DirectLighting::Exact, 64, 256, LightingSettings::kGatherCacheAuto};
    bool gatherGiven = false;   // gather from the config or the command line
    bool directSamplesGiven = false;  // direct_samples likewise
    // The speed/accuracy level (--quality, quality_level.h): photons, gather and direct_samples
    // where those are not given themselves. The defaults above are "standard"'s.
    std::string quality = kDefaultQuality;
    // 10^6 photons (TraceSettings' own 10^5 is for the library's callers). K as given: a run
    // traces with effectiveTrace's, capped at max_bounces.
    TraceSettings trace{1000000, 1, 32, EmissionAim{}, PhotonSampling{}};
    bool photonsGiven = false;  // photons from the config or the command line
    bool qmcBouncesGiven = false;  // K from the config or the command line (else the default, capped at maxBounces)
    UpdateSettings update;  // frames after the first (trackedGenerations has no option: TrackedPaths' most)
    int threads = 0;  // 0: all cores
    std::optional<FrameRange> frames;
    bool resume = false;  // continue outDir after its last complete frame (same fingerprint only)
    bool overwrite = false;  // replace another run's frames and timing.json in outDir
    std::string framesSource;  // where frames came from (the config or "command line"), for messages
    std::vector<PunctualLight> extraLights;  // world space, from the config
    EnvironmentSettings environment;         // a sky or an HDR map (--sky, --environment, "lights")
    float subdivide = 0;  // refine triangles with an edge longer than this (scene units) on the rest pose; 0: off
    float refineContacts = 0;  // refine edges within this of another piece of surface in any frame (contact_refinement.h); 0: off
    // Each output vertex's value: its own irradiance, or fitted over its triangles (vertex_fit.h).
    VertexFitKind vertexFit = VertexFitKind::Point;

    // Images (docs/design.md §7)
    int width = 640, height = 480;
    int samplesPerPixel = 1;
    bool writeExr = true, exrHalf = false, writePng = false;
    bool writeGltf = false;  // asset.glb: the scene file with the bake in it (lib/output/baked_asset.h)
    int gltfColourSet = -1;  // with writeGltf, the COLOR_n set to add, or -1
    bool writeUsd = false;   // asset.usda: the meshes with the bake as time-sampled colours (lib/output/usd_asset.h)
    // Each frame's files and the log only, never asset.glb or asset.usda (whatever writeGltf and writeUsd say): what a Slurm
    // array's chunk runs, its frames merged and the asset made once, from all of them.
    bool framesOnly = false;
    std::optional<float> exposure;        // PNG preview; unset: automatic from frame 0
    std::optional<int> cameraIndex;       // a glTF camera by index
    struct LookAt { Vec3f position, target, up{0, 1, 0}; float yfov = 0.8f; };
    std::optional<LookAt> camera;         // world space, from the config
    bool quiet = false;
    bool verbose = false;  // each frame's time on stderr
};

// Limits of qsgi's own formats and of sane runs. Values beyond them are refused with a message,
// never clamped or wrapped.
constexpr int64_t kMaxPhotons = int64_t(1) << 32;  // a segment's path index is 32 bits
constexpr int64_t kMaxBounces = int64_t(1) << 16;  // a segment's bounce field is 16 bits
constexpr int64_t kMaxK = int64_t(1) << 24;
constexpr int64_t kMaxThreads = 1024;
constexpr int64_t kMaxImageSide = 16384;
constexpr int64_t kMaxSamplesPerPixel = 4096;
constexpr int64_t kMaxSeed = INT64_MAX;
// --subdivide refuses a length that would make more triangles than this (about 40 GB of scene).
constexpr double kMaxRefinedTriangles = 2e8;

// `value` if it lies in [lo, hi], else InputError(source, place, "must lie in lo..hi" + why).
int64_t checkedInteger(int64_t value, int64_t lo, int64_t hi, const std::string& source, const std::string& place,
                       const std::string& why = "");
// A photon count: within 1..kMaxPhotons and within the machine's memory (each photon stores at
// least one segment and its path's start).
uint64_t checkedPhotons(int64_t value, const std::string& source, const std::string& place);

// The glTF animation an --animation value names: nullopt for a transform file, -1 for "gltf" (every
// animation of the scene at once), N for "gltf:N". Throws InputError for "gltf:" without a valid N.
std::optional<int> gltfAnimationSelector(const std::string& animation, const std::string& source);
constexpr double kDefaultGltfFps = 24;

// Parses "A:B" (inclusive, as in Blender) or "A". Throws InputError naming `source`.
FrameRange parseFrameRange(const std::string& text, const std::string& source);

// 1.5 % of the animation's bounding-box diagonal: a radius that means the same in any unit.
float defaultRadius(const Scene& scene);
// The same for bounds alone (qsgi compare, which has a PLY's vertices, not a scene).
constexpr float kDefaultRadiusFraction = 0.015f;  // of the animation's bounding-box diagonal
float defaultRadius(const Bounds3f& animationBounds);

// The trace settings a run uses: as given, but the default K is capped at max_bounces (an
// explicit K above it is refused by validateSettings); K means nothing under random and is 0 there.
TraceSettings effectiveTrace(const TraceSettings& trace);

}  // namespace qsgi
