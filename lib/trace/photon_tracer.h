// Photon tracing (docs/design.md §4): emits photons from the lights, follows them through diffuse
// bounces with Russian roulette and stores every segment in the ray cache.
#pragma once

#include <cstdint>
#include <memory>

#include "scene/scene.h"
#include "trace/envelope.h"
#include "trace/light_sampler.h"
#include "trace/photon_source.h"
#include "trace/ray_cache.h"
#include "trace/scene_bvh.h"
#include "trace/trace_settings.h"
#include "util/work_counter.h"

namespace qsgi {

static_assert(RayCache::kBytesPerPath == kLeastBytesPerPhoton, "a photon's least cost (trace_settings.h) is the cache's");

// What a first frame that later frames will update keeps beside its cache (TrackedPaths): per
// block of the cache, each path's segments from its first that meets `envelope` (continued
// `extension` past its impact) on, in path order. Found as the paths are traced, so that the
// cache is not decoded again to find them.
struct EnvelopeTails {
    Envelope envelope;
    float extension = 0;
    std::vector<std::vector<Segment>> blocks;  // filled by traceAll
};

class PhotonTracer {
public:
    PhotonTracer(const Scene& scene, const SceneBvh& bvh, const TraceSettings& settings);

    // Traces every photon from scratch. progress, if given, counts the photons done (its total set
    // here), from the worker threads as every other stage's.
    // tails, if given, also receives the tails that meet its envelope.
    RayCache traceAll(WorkCounter* progress = nullptr, EnvelopeTails* tails = nullptr) const;

    // Appends every segment of `path`.
    void tracePath(uint64_t path, std::vector<Segment>& out) const;
    // Appends the segments of `path` from bounce `bounce` on, continuing from the state the path
    // had there (origin, direction, power, whether its light was scattered) with the same numbers.
    void continuePath(uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction, Vec3f power, float tnear,
                      bool scattered, std::vector<Segment>& out) const;

    const LightSampler& lights() const { return source_->lights(); }
    // What decodes the caches it writes (and the tails it keeps).
    const std::shared_ptr<const PhotonSource>& source() const { return source_; }

private:
    // The one kernel of first traces and retraces, writing to a segment list or a cache block.
    template <class Out>
    void tracePathInto(uint64_t path, Out& out) const;
    template <class Out>
    void follow(const PathNumbers& numbers, uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction, Vec3f power,
                float tnear, bool scattered, Out& out) const;

    const SceneBvh& bvh_;
    TraceSettings settings_;
    // Shared with the caches it writes, which decode with it.
    std::shared_ptr<const PhotonSource> source_;
    Bounds3f bounds_;  // the animation's, padded: escaping segments end where they leave it
};

}  // namespace qsgi
