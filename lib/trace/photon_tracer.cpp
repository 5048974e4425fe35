#include "trace/photon_tracer.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <limits>

#include "trace/sampling.h"

namespace qsgi {

PhotonTracer::PhotonTracer(const Scene& scene, const SceneBvh& bvh, const TraceSettings& settings)
    : bvh_(bvh), settings_(settings),
      source_(std::make_shared<const PhotonSource>(scene, settings.photons, settings.seed, bvh.rayEpsilon(), settings.aim,
                                                   settings.sampling, bvh.sharedSurfaces(), &bvh)),
      bounds_(scene.animationBounds.expanded(bvh.rayEpsilon())) {}

namespace {
// Where the kernel puts a segment: a retrace's list, or the cache block a first trace writes.
void append(std::vector<Segment>& out, const Segment& s) { out.push_back(s); }
void append(RayCache::BlockWriter& out, const Segment& s) { out.add(s); }
// A first trace that also keeps tails: the block, and the current path's segments as traced.
struct BlockAndPath {
    RayCache::BlockWriter& block;
    std::vector<Segment>& path;
};
void append(BlockAndPath& out, const Segment& s) {
    out.block.add(s);
    out.path.push_back(s);
}
}  // namespace

void PhotonTracer::tracePath(uint64_t path, std::vector<Segment>& out) const { tracePathInto(path, out); }

template <class Out>
void PhotonTracer::tracePathInto(uint64_t path, Out& out) const {
    const PathNumbers numbers = source_->numbersFor(path);
    const PhotonEmission e = source_->lights().sample(numbers);
    if (!(maxComponent(e.power) > 0)) return;  // a spot light's photon outside its cone: nothing sent
    follow(numbers, path, 0, e.origin, e.direction, e.power, 0.0f, false, out);
}

void PhotonTracer::continuePath(uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction, Vec3f power,
                                float tnear, bool scattered, std::vector<Segment>& out) const {
    follow(source_->numbersFor(path), path, bounce, origin, direction, power, tnear, scattered, out);
}

template <class Out>
void PhotonTracer::follow(const PathNumbers& rng, uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction,
                          Vec3f power, float tnear, bool scattered, Out& out) const {
    using namespace rng_dim;
    const float eps = bvh_.rayEpsilon();
    for (; bounce < settings_.maxBounces; ++bounce) {
        Segment s;
        s.origin = origin;
        s.direction = direction;
        s.power = power;
        s.path = uint32_t(path);
        s.bounce = uint16_t(bounce);
        s.scattered = scattered;
        const auto hit = bvh_.intersect(origin, direction, tnear, std::numeric_limits<float>::infinity());
        if (!hit) {
            s.length = bounds_.exitDistance(origin, direction);
            append(out, s);
            return;
        }
        const PhotonSource::Surface surface = source_->surfaceAt(hit->triangle, hit->u, hit->v);
        s.length = hit->t;
        s.triangle = hit->triangle;
        s.impactDynamic = surface.dynamic;
        s.impactVaries = surface.varies;
        if (surface.varies) s.b1 = hit->u, s.b2 = hit->v;
        append(out, s);

        // Straight through a pane (its share T), or Russian roulette on the albedo at the hit and
        // a cosine-weighted bounce on the incoming side.
        const PhotonSource::Impact what = PhotonSource::impact(surface, rng.uniform(bounce + 1, kSurvival));
        if (what == PhotonSource::Impact::Stops) return;
        power = PhotonSource::powerAfter(power, surface, what);
        // The hit's own normal (first traces and retraces both take it from Embree).
        Vec3f n = normalize(hit->ng);
        if (dot(n, direction) > 0) n = -n;
        if (what == PhotonSource::Impact::Passes) {
            origin = s.impactPoint() - n * eps;  // just past the pane, on the far side
            tnear = 0;
            continue;
        }
        origin = s.impactPoint() + n * eps;
        direction = cosineHemisphere(n, rng.uniform(bounce + 1, kScatterDirection0), rng.uniform(bounce + 1, kScatterDirection1));
        scattered = true;
        tnear = 0;
    }
}

RayCache PhotonTracer::traceAll(WorkCounter* progress, EnvelopeTails* tails) const {
    const LightSampler& lights = source_->lights();
    const uint64_t n = settings_.photons;
    if (progress) progress->setTotal(n);
    // Fixed chunks of paths, each written as one block of the cache: the cache is the same for
    // any thread count, and the blocks are kept as they are (no concatenation).
    constexpr uint64_t kChunk = 4096;
    const uint64_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<RayCache::BlockWriter> blocks(chunks);
    if (tails) tails->blocks.assign(chunks, {});
    // Each thread writes its chunks into one writer and keeps an exact-size copy of each.
    tbb::enumerable_thread_specific<RayCache::BlockWriter> writers;
    tbb::enumerable_thread_specific<std::vector<Segment>> paths;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, chunks, 1), [&](const tbb::blocked_range<uint64_t>& r) {
        RayCache::BlockWriter& block = writers.local();
        std::vector<Segment>& path = paths.local();
        for (uint64_t c = r.begin(); c != r.end(); ++c) {
            const uint64_t begin = c * kChunk, end = std::min(n, (c + 1) * kChunk);
            block.clear();
            for (uint64_t p = begin; p < end; ++p) {
                block.beginPath();
                if (lights.empty()) continue;
                if (!tails) {
                    tracePathInto(p, block);
                    continue;
                }
                path.clear();
                BlockAndPath out{block, path};
                tracePathInto(p, out);
                tails->envelope.appendTail(path.data(), path.data() + path.size(), tails->extension, tails->blocks[c]);
            }
            blocks[c] = block.exactCopy();
            if (progress) progress->add(end - begin);
        }
    });
    return RayCache::ofBlocks(std::move(blocks), kChunk, source_, lights.maxPhotonPower());
}

}  // namespace qsgi
