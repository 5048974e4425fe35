#include "trace/photon_tracer.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <limits>
#include <thread>

#include "trace/sampling.h"

namespace qsgi {

PhotonTracer::PhotonTracer(const Scene& scene, const SceneBvh& bvh, const TraceSettings& settings)
    : bvh_(bvh), settings_(settings),
      lights_(scene, settings.photons, bvh.rayEpsilon(), settings.aim,
              settings.sampling.kind == SamplerKind::Sobol ? std::optional<uint64_t>(settings.seed) : std::nullopt),
      bounds_(scene.animationBounds.expanded(bvh.rayEpsilon())) {
    surfaces_.resize(scene.triangleCount());
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Vec3f albedo = scene.materials[scene.triangleMaterial[t]].albedo;
        surfaces_[t] = Surface{albedo, maxComponent(albedo), scene.triangleDynamic[t]};
    }
}

PathNumbers PhotonTracer::numbersFor(uint64_t path) const {
    if (settings_.sampling.kind == SamplerKind::Random) return PathNumbers(settings_.seed, path);
    const LightSampler::Deal deal = lights_.dealt(path);
    return PathNumbers(settings_.seed, path, deal.emitter, deal.index, settings_.sampling.qmcBounces);
}

void PhotonTracer::tracePath(uint64_t path, std::vector<Segment>& out) const {
    const PathNumbers numbers = numbersFor(path);
    const PhotonEmission e = lights_.sample(numbers);
    if (!(maxComponent(e.power) > 0)) return;  // a spot light's photon outside its cone: nothing sent
    follow(numbers, path, 0, e.origin, e.direction, e.power, 0.0f, out);
}

void PhotonTracer::continuePath(uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction, Vec3f power,
                                float tnear, std::vector<Segment>& out) const {
    follow(numbersFor(path), path, bounce, origin, direction, power, tnear, out);
}

void PhotonTracer::follow(const PathNumbers& rng, uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction,
                          Vec3f power, float tnear, std::vector<Segment>& out) const {
    using namespace rng_dim;
    const float eps = bvh_.rayEpsilon();
    for (; bounce < settings_.maxBounces; ++bounce) {
        Segment s;
        s.origin = origin;
        s.direction = direction;
        s.power = power;
        s.path = uint32_t(path);
        s.bounce = uint16_t(bounce);
        const auto hit = bvh_.intersect(origin, direction, tnear, std::numeric_limits<float>::infinity());
        if (!hit) {
            s.length = bounds_.exitDistance(origin, direction);
            out.push_back(s);
            return;
        }
        const Surface& surface = surfaces_[hit->triangle];
        s.length = hit->t;
        s.triangle = hit->triangle;
        s.impactDynamic = surface.dynamic;
        out.push_back(s);

        // Russian roulette on the albedo, then a cosine-weighted bounce on the incoming side.
        if (!(rng.uniform(bounce + 1, kSurvival) < surface.survival)) return;
        power = power * surface.albedo / surface.survival;
        // The hit's own normal (first traces and retraces both take it from Embree).
        Vec3f n = normalize(hit->ng);
        if (dot(n, direction) > 0) n = -n;
        origin = s.impactPoint() + n * eps;
        direction = cosineHemisphere(n, rng.uniform(bounce + 1, kScatterDirection0), rng.uniform(bounce + 1, kScatterDirection1));
        tnear = 0;
    }
}

RayCache PhotonTracer::traceAll(const std::function<void(uint64_t, uint64_t)>& progress) const {
    RayCache cache;
    cache.maxPhotonPower = lights_.maxPhotonPower();
    const uint64_t n = settings_.photons;
    // Fixed chunks, concatenated in chunk order: the cache is the same for any thread count.
    constexpr uint64_t kChunk = 4096;
    const uint64_t chunks = (n + kChunk - 1) / kChunk;
    std::vector<std::vector<Segment>> chunkSegments(chunks);
    std::vector<std::vector<uint32_t>> chunkPathLengths(chunks);
    std::atomic<uint64_t> done{0}, stored{0};
    std::atomic<bool> finished{false};
    std::thread reporter;
    if (progress) {
        reporter = std::thread([&] {
            while (!finished.load()) {
                progress(done.load(), n);
                std::this_thread::sleep_for(std::chrono::milliseconds(200));
            }
        });
    }
    auto work = [&](const tbb::blocked_range<uint64_t>& r) {
        for (uint64_t c = r.begin(); c != r.end(); ++c) {
            auto& segs = chunkSegments[c];
            auto& lengths = chunkPathLengths[c];
            const uint64_t end = std::min(n, (c + 1) * kChunk);
            // Room for the segments the chunks so far averaged, and a quarter more: growing a
            // chunk from empty copied it several times over.
            const double perPhoton = double(stored.load()) / double(std::max<uint64_t>(done.load(), 1));
            segs.reserve(size_t(double(end - c * kChunk) * std::max(perPhoton, 1.0) * 1.25));
            lengths.reserve(end - c * kChunk);
            for (uint64_t p = c * kChunk; p < end; ++p) {
                const size_t before = segs.size();
                tracePath(p, segs);
                lengths.push_back(uint32_t(segs.size() - before));
            }
            stored += segs.size();
            done += end - c * kChunk;
        }
    };
    try {
        if (!lights_.empty()) tbb::parallel_for(tbb::blocked_range<uint64_t>(0, chunks, 1), work);
    } catch (...) {
        finished = true;
        if (reporter.joinable()) reporter.join();
        throw;
    }
    finished = true;
    if (reporter.joinable()) reporter.join();
    if (progress) progress(n, n);

    // Chunks are concatenated in chunk order, copied in parallel: a serial copy was a tenth of
    // the time at 10^6 photons.
    std::vector<uint64_t> chunkBegin(chunks + 1, 0);
    for (uint64_t c = 0; c < chunks; ++c) chunkBegin[c + 1] = chunkBegin[c] + chunkSegments[c].size();
    cache.segments.resize(chunkBegin[chunks]);
    cache.pathBegin.resize(n + 1);
    cache.pathBegin[0] = 0;
    tbb::parallel_for(uint64_t(0), chunks, [&](uint64_t c) {
        std::copy(chunkSegments[c].begin(), chunkSegments[c].end(), cache.segments.begin() + int64_t(chunkBegin[c]));
        std::vector<Segment>().swap(chunkSegments[c]);
        uint64_t at = chunkBegin[c], path = c * kChunk;
        for (uint32_t len : chunkPathLengths[c]) cache.pathBegin[++path] = (at += len);
    });
    if (lights_.empty()) cache.pathBegin.assign(n + 1, 0);
    return cache;
}

}  // namespace qsgi
