#include "trace/photon_tracer.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <limits>
#include <thread>

#include "trace/sampling.h"

namespace qsgi {

PhotonTracer::PhotonTracer(const Scene& scene, const SceneBvh& bvh, const TraceSettings& settings)
    : scene_(scene), bvh_(bvh), settings_(settings), lights_(scene, settings.photons, bvh.rayEpsilon(), settings.aim),
      bounds_(scene.animationBounds.expanded(bvh.rayEpsilon())) {}

void PhotonTracer::tracePath(uint64_t path, std::vector<Segment>& out) const {
    const PhotonEmission e = lights_.sample(PhotonRandom(settings_.seed, path));
    if (!(maxComponent(e.power) > 0)) return;  // a spot light's photon outside its cone: nothing sent
    continuePath(path, 0, e.origin, e.direction, e.power, 0.0f, out);
}

void PhotonTracer::continuePath(uint64_t path, uint32_t bounce, Vec3f origin, Vec3f direction, Vec3f power,
                                float tnear, std::vector<Segment>& out) const {
    using namespace rng_dim;
    const PhotonRandom rng(settings_.seed, path);
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
        s.length = hit->t;
        s.triangle = hit->triangle;
        s.impactDynamic = scene_.triangleDynamic[hit->triangle];
        out.push_back(s);

        // Russian roulette on the albedo, then a cosine-weighted bounce on the incoming side.
        const Vec3f albedo = scene_.materials[scene_.triangleMaterial[hit->triangle]].albedo;
        const float survival = maxComponent(albedo);
        if (!(rng.uniform(bounce + 1, kSurvival) < survival)) return;
        power = power * albedo / survival;
        Vec3f n = scene_.geometricNormal(hit->triangle);
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
    std::atomic<uint64_t> done{0};
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
            for (uint64_t p = c * kChunk; p < end; ++p) {
                const size_t before = segs.size();
                tracePath(p, segs);
                lengths.push_back(uint32_t(segs.size() - before));
            }
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

    size_t total = 0;
    for (const auto& s : chunkSegments) total += s.size();
    cache.segments.reserve(total);
    cache.pathBegin.reserve(n + 1);
    cache.pathBegin.push_back(0);
    for (uint64_t c = 0; c < chunks; ++c) {
        cache.segments.insert(cache.segments.end(), chunkSegments[c].begin(), chunkSegments[c].end());
        for (uint32_t len : chunkPathLengths[c]) cache.pathBegin.push_back(cache.pathBegin.back() + len);
        std::vector<Segment>().swap(chunkSegments[c]);
    }
    if (lights_.empty()) cache.pathBegin.assign(n + 1, 0);
    return cache;
}

}  // namespace qsgi
