// What photon tracing reads (docs/design.md §4): how many photons, their seed and longest path,
// where the lights aim them and where their numbers come from. A light header: the option table
// (lib/pipeline/render_options.cpp) sets these fields directly, and the part of qsgi that reads
// inputs includes it without any of tracing.
#pragma once

#include <cstddef>
#include <cstdint>

#include "util/enum_names.h"

namespace qsgi {

// Where a path's numbers come from (photon_numbers.h): an Owen-scrambled Sobol point per photon
// for the emission and the first K scatterings, or every number hashed.
enum class SamplerKind : uint8_t { Sobol, Random };
inline constexpr NamedValue<SamplerKind> kSamplerNames[] = {{SamplerKind::Sobol, "sobol"}, {SamplerKind::Random, "random"}};
inline const char* samplerName(SamplerKind kind) { return nameOf(kSamplerNames, kind); }

// The scatterings the shipped Sobol table can cover (photon_numbers.h checks it against the table).
constexpr uint32_t kMaxQmcBounces = 32;

struct PhotonSampling {
    SamplerKind kind = SamplerKind::Sobol;
    uint32_t qmcBounces = 2;  // scatterings whose survival and direction come from the Sobol point
};

// How emission is aimed (light_sampler.h). margin: how far from geometry a first segment still
// counts (DETP's disc radius: segments that pass beside an open edge cross its discs; 0 for
// estimators that count impacts only).
struct EmissionAim {
    bool enabled = true;
    float margin = 0;
};

struct TraceSettings {
    uint64_t photons = 100000;
    uint64_t seed = 1;
    uint32_t maxBounces = 32;
    EmissionAim aim;  // on by default; its margin is the estimator's reach (FrameSolver sets it)
    PhotonSampling sampling;
};

// The least a photon costs in the ray cache: its path's start and first segment (RayCache's
// kBytesPerPath; photon_tracer.h checks they agree). Bounds the photon count by the memory.
constexpr size_t kLeastBytesPerPhoton = 12;

}  // namespace qsgi
