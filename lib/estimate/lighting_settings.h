// How a vertex's irradiance is put together from the photons (docs/design.md §5.1, issue 33): either
// all of it from the photons' density estimate (the paper's method), or direct light exact by
// shadow rays plus — with a final gather — one bounce gathered over the photon solution.
#pragma once

#include <cstddef>
#include <cstdint>

#include "util/enum_names.h"

namespace qsgi {

enum class DirectLighting { Photons, Exact };
inline constexpr NamedValue<DirectLighting> kDirectLightingNames[] = {{DirectLighting::Photons, "photons"},
                                                                      {DirectLighting::Exact, "exact"}};
inline const char* directLightingName(DirectLighting d) { return nameOf(kDirectLightingNames, d); }

// The defaults here are the paper's method, which the library's callers (tests, benchmarks) get
// unless they ask; the renderer's defaults (RenderSettings) are exact direct light and a gather.
struct LightingSettings {
    // Photons: E_v is the estimator's answer. Exact: E_v = D_v + (gatherRays > 0 ? the gathered
    // mean of the first pass : the estimator's answer after the first bounce).
    DirectLighting direct = DirectLighting::Photons;
    // Shadow rays per vertex toward the emissive triangles (one per punctual light besides).
    uint32_t directSamples = 16;
    // Final-gather rays per vertex (0: no gather).
    uint32_t gatherRays = 0;
    // The gather cache's tolerance A (GatherCache: records spaced A times the distance to the
    // geometry around them; 0: every vertex a record, the per-vertex gather's bits),
    // kGatherCacheOff (every vertex gathers: no probes, no records) or kGatherCacheAuto (resolved
    // for the scene by resolvedFor).
    float gatherCache = kGatherCacheOff;
    static constexpr float kGatherCacheOff = -1, kGatherCacheAuto = -2;
    // What auto resolves to: the cache at this tolerance on scenes of at least this many vertices,
    // where it was measured to win per second (docs/method.md, the gather cache: data/cornell's
    // 21,636 vertices reach the per-vertex gather's error in 0.73x its time, a 5.3·10⁵-vertex
    // floor's frame takes half the time; on scenes of 2–6·10³ vertices the gather is a small part
    // of a frame and the cache at best ties), otherwise off.
    static constexpr float kAutoTolerance = 0.2f;
    // The rays every vertex casts under the cache (the first of its M; GatherCache): 16 Sobol
    // points spread well over the hemisphere, a sixteenth of a full gather at 256 rays.
    static constexpr uint32_t kGatherProbeRays = 16;
    static constexpr size_t kAutoMinVertices = 10000;

    bool exactDirect() const { return direct == DirectLighting::Exact; }
    bool gathers() const { return exactDirect() && gatherRays > 0; }
    // Needs gatherCache resolved (not auto). With no more rays than the probes every vertex
    // gathers in full anyway: no cache.
    bool cachesGather() const { return gathers() && gatherCache >= 0 && gatherRays > kGatherProbeRays; }
    // These settings with an auto cache resolved for a scene of `vertices` vertices.
    LightingSettings resolvedFor(size_t vertices) const {
        LightingSettings r = *this;
        if (r.gatherCache == kGatherCacheAuto) r.gatherCache = vertices >= kAutoMinVertices ? kAutoTolerance : kGatherCacheOff;
        return r;
    }
};

// Limits of the options: a vertex's samples are points of one Sobol sequence, indexed by 32 bits.
constexpr int64_t kMaxDirectSamples = int64_t(1) << 16;
constexpr int64_t kMaxGatherRays = int64_t(1) << 16;

}  // namespace qsgi
