// Density-estimation benchmarks on data/cornell (issue 4): each estimator at 10^5 and 10^6
// photons and r in {0.02, 0.05, 0.1}: indexed vs brute force (10^5 only: brute force at 10^6
// takes minutes), sorted vs unsorted queries, and DETP's FLANN candidates vs the exact index with
// the approximation's error; DETP's boundary rules (clip, linear, paper) and the cost of the disc
// regions they need (per radius, with and without the photon map's coverage probes). Photon
// tracing and DETP's disc traversal, each next to its ceiling: Embree alone on the same rays
// (closest hit through the triangles; all hits through the discs). Counters carry the work
// done, so ratios can be read within one run.
#include <benchmark/benchmark.h>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>

#include "embree_scenes.h"
#include "estimate/accuracy.h"
#include "estimate/detp.h"
#include "estimate/estimator.h"
#include "scene/gltf_loader.h"
#include "trace/photon_tracer.h"

using namespace qsgi;

namespace {

// The scene and traced photon sets, made once per process and shared by the benchmarks.
struct CornellFixture {
    Scene scene;
    EmbreeDevice device;
    std::unique_ptr<SceneBvh> bvh;
    std::map<std::pair<int, bool>, std::unique_ptr<DiscRegions>> regions;
    std::map<uint64_t, std::unique_ptr<RayCache>> caches;
    std::map<std::pair<uint64_t, int>, std::vector<Vec3f>> exactDetp;

    CornellFixture() {
        Warnings w;
        scene = loadGltfScene(QSGI_SOURCE_DIR "/data/cornell/cornell.gltf", w);
        bvh = std::make_unique<SceneBvh>(device, scene);
    }
    const DiscRegions& discRegions(int radiusMm, bool coverage) {
        auto& r = regions[{radiusMm, coverage}];
        if (!r) {
            r = std::make_unique<DiscRegions>(radiusMm / 1000.0f, coverage);
            r->computeAll(scene, *bvh);
        }
        return *r;
    }
    const RayCache& cache(uint64_t photons) {
        auto& c = caches[photons];
        if (!c) c = std::make_unique<RayCache>(PhotonTracer(scene, *bvh, TraceSettings{photons, 1, 32, EmissionAim{}, PhotonSampling{}}).traceAll());
        return *c;
    }
    // The cache's segments decoded, for the ceilings: plain rays prepared before any timed loop.
    const std::vector<Segment>& decoded(uint64_t photons) {
        auto& d = decodedSegments[photons];
        if (d.empty()) d = cache(photons).decodeAll();
        return d;
    }
    std::map<uint64_t, std::vector<Segment>> decodedSegments;
    const std::vector<Vec3f>& exact(uint64_t photons, int radiusMm) {
        auto& e = exactDetp[{photons, radiusMm}];
        if (e.empty()) {
            EstimatorSettings s;
            s.kind = EstimatorKind::Detp;
            s.radius = radiusMm / 1000.0f;
            e = estimateVertexRadiosity(scene, *bvh, cache(photons), s, device, &discRegions(radiusMm, false)).irradiance;
        }
        return e;
    }
};

CornellFixture& fixture() {
    static CornellFixture f;
    return f;
}

enum Mode { kIndexedSorted = 0, kIndexedUnsorted = 1, kBruteForce = 2, kFlannCandidates = 3 };

void BM_Estimate(benchmark::State& state) {
    const auto kind = EstimatorKind(state.range(0));
    const uint64_t photons = uint64_t(state.range(1));
    const int radiusMm = int(state.range(2));
    const auto mode = Mode(state.range(3));
    const auto rule = DetpBoundary(state.range(4));
    CornellFixture& f = fixture();
    const RayCache& cache = f.cache(photons);
    EstimatorSettings s;
    s.kind = kind;
    s.radius = radiusMm / 1000.0f;
    s.photonMap.k = 50;
    s.useIndex = mode != kBruteForce;
    s.sortQueries = mode != kIndexedUnsorted;
    s.detp.index = mode == kFlannCandidates ? DetpIndex::Flann : DetpIndex::Embree;
    s.detp.boundary = rule;
    // Regions are made once (BM_DiscRegions times them): this measures the estimate alone.
    const DiscRegions* regions = needsDiscRegions(s) ? &f.discRegions(radiusMm, kind == EstimatorKind::PhotonMap) : nullptr;
    VertexRadiosity result;
    for (auto _ : state) {
        result = estimateVertexRadiosity(f.scene, *f.bvh, cache, s, f.device, regions);
        benchmark::DoNotOptimize(result.irradiance.data());
    }
    state.counters["segments"] = double(cache.segmentCount());
    if (kind == EstimatorKind::Detp && mode == kFlannCandidates) {
        const ErrorStats e = errorStats(result.irradiance, f.exact(photons, radiusMm));
        state.counters["rel_rms_vs_exact"] = e.relativeRms;
        state.counters["rel_bias_vs_exact"] = e.relativeBias;
    }
    static const char* modes[] = {"indexed+sorted", "indexed+unsorted", "brute-force", "flann-candidates"};
    state.SetLabel(std::string(estimatorName(kind)) + " " + modes[mode] +
                   (kind == EstimatorKind::ImpactCount ? "" : std::string(" ") + detpBoundaryName(rule)));
}

// Own surfaces, reachable cells (and the photon map's coverage probes) of every vertex: the cost
// of frame 0, and of any frame for the vertices a mover touches.
void BM_DiscRegions(benchmark::State& state) {
    CornellFixture& f = fixture();
    const float radius = float(state.range(0)) / 1000.0f;
    const bool coverage = state.range(1) != 0;
    for (auto _ : state) {
        DiscRegions regions(radius, coverage);
        regions.computeAll(f.scene, *f.bvh);
        benchmark::DoNotOptimize(regions.size());
    }
    state.counters["vertices"] = double(f.scene.vertexCount());
    state.SetLabel(coverage ? "reachable + covered cells" : "reachable cells");
}

void BM_TracePhotons(benchmark::State& state) {
    CornellFixture& f = fixture();
    const uint64_t photons = uint64_t(state.range(0));
    // Second argument: the sampler (0 Sobol with the default K, 1 random): the Sobol points'
    // cost beside the hashed numbers'.
    PhotonSampling sampling;
    if (state.range(1) == 1) sampling.kind = SamplerKind::Random;
    SceneBvh bvh(f.device, f.scene);
    const PhotonTracer tracer(f.scene, bvh, TraceSettings{photons, 1, 32, EmissionAim{}, sampling});
    size_t segments = 0;
    for (auto _ : state) {
        const RayCache cache = tracer.traceAll();
        segments = cache.segmentCount();
    }
    state.counters["segments_per_s"] = benchmark::Counter(double(segments), benchmark::Counter::kIsIterationInvariantRate);
    // What the ray cache holds per segment, its records and path index together.
    const RayCache& cache = f.cache(photons);
    state.counters["bytes_per_segment"] = double(cache.bytes()) / double(cache.segmentCount());
}

// Reading the whole cache: every segment decoded in (path, bounce) order, in parallel, as the
// estimators read it.
void BM_DecodeRayCache(benchmark::State& state) {
    CornellFixture& f = fixture();
    const RayCache& cache = f.cache(uint64_t(state.range(0)));
    for (auto _ : state) {
        const std::vector<Segment> all = cache.decodeAll();
        benchmark::DoNotOptimize(all.data());
    }
    state.counters["segments_per_s"] =
        benchmark::Counter(double(cache.segmentCount()), benchmark::Counter::kIsIterationInvariantRate);
}

// The ceiling BM_TracePhotons is read against: Embree's own closest-hit rate on the same
// triangles, configured as SceneBvh configures them (one robust, high-quality BVH; the fixture
// marks nothing dynamic, so the static/dynamic split is this one scene; the same tie filter and
// context), replaying the tracer's segments (their origins and directions, decoded before the
// timed loop, in the tracer's order: incoherent after the first bounce) on all cores as the
// tracer runs. Tracer segments/s over this rays/s is the share of the hardware's pace we reach.
void BM_EmbreeClosestHitCeiling(benchmark::State& state) {
    CornellFixture& f = fixture();
    const std::vector<Segment>& segments = f.decoded(uint64_t(state.range(0)));
    const WholeEmbreeScene scene(f.device, f.scene, WholeEmbreeScene::Config::AsSceneBvh);
    const float epsilon = f.bvh->rayEpsilon();
    for (auto _ : state) {
        const size_t hits = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, segments.size(), 4096), size_t(0),
            [&](const tbb::blocked_range<size_t>& range, size_t count) {
                for (size_t i = range.begin(); i < range.end(); ++i) {
                    const Segment& s = segments[i];
                    RTCRayHit rayHit{};
                    rayHit.ray.org_x = s.origin.x, rayHit.ray.org_y = s.origin.y, rayHit.ray.org_z = s.origin.z;
                    rayHit.ray.dir_x = s.direction.x, rayHit.ray.dir_y = s.direction.y, rayHit.ray.dir_z = s.direction.z;
                    rayHit.ray.tnear = epsilon;
                    rayHit.ray.tfar = std::numeric_limits<float>::infinity();
                    rayHit.ray.mask = ~0u;
                    rayHit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    TieBreakContext context;
                    rtcInitIntersectContext(&context.base);
                    rtcIntersect1(scene.get(), &context.base, &rayHit);
                    count += rayHit.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                }
                return count;
            },
            std::plus<size_t>());
        benchmark::DoNotOptimize(hits);
    }
    state.counters["rays_per_s"] =
        benchmark::Counter(double(segments.size()), benchmark::Counter::kIsIterationInvariantRate);
}

// DETP's own rate: every segment traced through the vertices' discs with the exact test, in the
// Morton order the estimator uses (docs/design.md §5). Its ceiling is BM_EmbreeAllHitsCeiling below.
// Third argument: 0 times the pass alone, on segments decoded and ordered before the timed loop;
// 1 runs it as the estimator does, decoding the cache a group of blocks at a time (what reading
// the compact cache costs the pass).
void BM_DetpSegments(benchmark::State& state) {
    CornellFixture& f = fixture();
    const RayCache& cache = f.cache(uint64_t(state.range(0)));
    const float radius = float(state.range(1)) / 1000.0f;
    const bool fromCache = state.range(2) == 1;
    const DetpDiscs discs(f.device, f.scene, radius, DetpBoundary::Clip, &f.discRegions(int(state.range(1)), false), f.bvh.get());
    const PowerQuantizer q(cache.maxPhotonPower);
    const std::vector<Segment> ordered =
        fromCache ? std::vector<Segment>() : segmentsInQueryOrder(cache, 0, cache.blockCount(), true);
    DetpQueryStats stats;
    for (auto _ : state) {
        stats = DetpQueryStats();
        const auto sums = fromCache ? discs.sums(cache, true, q, &stats) : discs.sums(ordered, q, &stats);
        benchmark::DoNotOptimize(sums.data());
    }
    state.counters["segments_per_s"] =
        benchmark::Counter(double(cache.segmentCount()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["disc_hits_per_segment"] = double(stats.discHits) / double(cache.segmentCount());
}

// What Embree alone does with the same rays through the same discs: one BVH of oriented discs at
// every vertex (DETP's enlarged search radius), each segment traced over DETP's extent (from just
// before its origin to r past its impact, or out of the animation's padded bounds if it escapes),
// in the same Morton order, with a filter that only counts each hit and rejects it so traversal
// goes on (all hits). No exact test, no regions, no sums: the pace DETP's traversal could reach.
struct CountingContext {
    RTCIntersectContext base;  // first member: Embree hands back a pointer to it
    size_t hits = 0;
};

void countAndReject(const RTCFilterFunctionNArguments* args) {
    auto* ctx = reinterpret_cast<CountingContext*>(args->context);
    for (unsigned i = 0; i < args->N; ++i)
        if (args->valid[i] != 0) {
            ++ctx->hits;
            args->valid[i] = 0;
        }
}

void BM_EmbreeAllHitsCeiling(benchmark::State& state) {
    CornellFixture& f = fixture();
    const RayCache& cache = f.cache(uint64_t(state.range(0)));
    const float radius = float(state.range(1)) / 1000.0f;
    const float eps = f.scene.sceneEpsilon();
    const float slack = 1e-4f * radius + eps, searchRadius = radius * (1 + 1e-3f) + eps;  // as DetpDiscs
    const Bounds3f escapeBounds = f.scene.animationBounds.expanded(radius + 2 * slack);
    RTCScene scene = rtcNewScene(f.device.get());
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);  // DetpDiscs' flags and quality
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geometry = rtcNewGeometry(f.device.get(), RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    const size_t n = f.scene.vertexCount();
    auto* vertex = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
    auto* normal = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_NORMAL, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), n));
    for (size_t v = 0; v < n; ++v) {
        for (int c = 0; c < 3; ++c) vertex[4 * v + c] = f.scene.positions[v][c], normal[3 * v + c] = f.scene.normals[v][c];
        vertex[4 * v + 3] = searchRadius;
    }
    rtcSetGeometryIntersectFilterFunction(geometry, countAndReject);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
    const std::vector<Segment> ordered = segmentsInQueryOrder(cache, 0, cache.blockCount(), true);
    size_t hits = 0;
    for (auto _ : state) {
        hits = tbb::parallel_reduce(
            tbb::blocked_range<size_t>(0, ordered.size(), 256), size_t(0),
            [&](const tbb::blocked_range<size_t>& range, size_t count) {
                CountingContext ctx;
                rtcInitIntersectContext(&ctx.base);
                for (size_t i = range.begin(); i < range.end(); ++i) {
                    const Segment& s = ordered[i];
                    float end = s.length + radius;
                    if (!s.hasImpact()) end = std::max(end, escapeBounds.exitDistance(s.origin, s.direction));
                    const Vec3f o = s.origin - s.direction * slack;
                    RTCRayHit rh{};
                    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
                    rh.ray.dir_x = s.direction.x, rh.ray.dir_y = s.direction.y, rh.ray.dir_z = s.direction.z;
                    rh.ray.tnear = 0;
                    rh.ray.tfar = end + 2 * slack;
                    rh.ray.mask = ~0u;
                    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                    rtcIntersect1(scene, &ctx.base, &rh);
                }
                return count + ctx.hits;
            },
            std::plus<size_t>());
        benchmark::DoNotOptimize(hits);
    }
    rtcReleaseScene(scene);
    state.counters["rays_per_s"] =
        benchmark::Counter(double(ordered.size()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["disc_hits_per_segment"] = double(hits) / double(ordered.size());
}

void estimatorArguments(benchmark::internal::Benchmark* b) {
    const int64_t clip = int64_t(DetpBoundary::Clip), linear = int64_t(DetpBoundary::Linear),
                  paper = int64_t(DetpBoundary::Paper);
    for (int64_t photons : {100000, 1000000}) {
        b->Args({int64_t(EstimatorKind::ImpactCount), photons, 0, kIndexedSorted, clip});
        for (int64_t radius : {20, 50, 100}) {
            for (int64_t kind : {int64_t(EstimatorKind::PhotonMap), int64_t(EstimatorKind::Detp)}) {
                b->Args({kind, photons, radius, kIndexedSorted, clip});
                b->Args({kind, photons, radius, kIndexedSorted, paper});
                b->Args({kind, photons, radius, kIndexedUnsorted, clip});
                if (photons == 100000) b->Args({kind, photons, radius, kBruteForce, clip});
            }
            b->Args({int64_t(EstimatorKind::Detp), photons, radius, kIndexedSorted, linear});
            b->Args({int64_t(EstimatorKind::Detp), photons, radius, kFlannCandidates, clip});
        }
    }
    b->ArgNames({"estimator", "photons", "radius_mm", "mode", "boundary"});
}

// Issue 12's wasteful case: a third-party model lit from a config, a point light 2 m from it and
// a directional light (../shared's FlightHelmet), made once per process like CornellFixture.
// Both benchmarks trace kPhotons; DETP's default radius for this model, 1.5 % of its
// diagonal, is 13 mm.
struct FlightHelmetFixture {
    static constexpr uint64_t kPhotons = 200000;
    static constexpr float kDetpRadius = 0.013f;
    Scene scene;
    EmbreeDevice device;
    std::unique_ptr<SceneBvh> bvh;  // null where ../shared is absent

    FlightHelmetFixture() {
        const std::string path =
            QSGI_SOURCE_DIR "/../shared/data/gltf-samples/models/FlightHelmet/glTF/FlightHelmet.gltf";
        if (!std::ifstream(path)) return;
        Warnings w;
        scene = loadGltfScene(path, w);
        PunctualLight point;
        point.type = LightType::Point;
        point.position = Vec3f(Vec3d(0.0, 0.3, 2.0) - scene.worldOrigin);
        point.intensity = Vec3f(10.0f);
        PunctualLight sun;
        sun.type = LightType::Directional;
        sun.direction = normalize(Vec3f(0.0f, -1.0f, -0.3f));
        sun.intensity = Vec3f(2.0f);
        scene.lights = {point, sun};
        bvh = std::make_unique<SceneBvh>(device, scene);
    }
    RayCache trace(const EmissionAim& aim) const {
        return PhotonTracer(scene, *bvh, TraceSettings{kPhotons, 1, 32, aim, PhotonSampling{}}).traceAll();
    }
};

// The fixture, or null (and the benchmark skipped) where ../shared is absent.
const FlightHelmetFixture* flightHelmet(benchmark::State& state) {
    static const FlightHelmetFixture f;
    if (!f.bvh) {
        state.SkipWithError("../shared/data/gltf-samples (FlightHelmet) is absent beside the repository");
        return nullptr;
    }
    return &f;
}

// Each iteration builds the tracer (projection maps included) and traces; landed_photons_per_s
// counts photons whose first segment hits geometry. margin_mm: the reach the maps keep beside
// geometry (13 for DETP; 0 for estimators that count impacts only).
void BM_FlightHelmetEmission(benchmark::State& state) {
    const FlightHelmetFixture* f = flightHelmet(state);
    if (!f) return;
    const EmissionAim aim{state.range(0) != 0, float(state.range(1)) / 1000.0f};
    uint64_t landed = 0;
    for (auto _ : state) landed = f->kPhotons - f->trace(aim).pathsMissingScene();
    state.counters["landed_photons_per_s"] = benchmark::Counter(double(landed), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["missed_fraction"] = 1.0 - double(landed) / double(f->kPhotons);
}

// What DETP makes of the photons aimed within its radius of the geometry: a first segment that
// hits nothing still counts where it crosses a disc beside an open edge or a silhouette (the
// `clip` rule). wasted_fraction: photons whose first segment neither hits geometry nor crosses
// any disc that counts; missed_fraction as above. Measured once: it is a count.
void BM_FlightHelmetDetpWaste(benchmark::State& state) {
    const FlightHelmetFixture* f = flightHelmet(state);
    if (!f) return;
    const float radius = f->kDetpRadius;
    uint64_t missed = 0, wasted = 0;
    for (auto _ : state) {
        DiscRegions regions(radius, false);
        regions.computeAll(f->scene, *f->bvh);
        const DetpDiscs discs(f->device, f->scene, radius, DetpBoundary::Clip, &regions, f->bvh.get());
        const RayCache cache = f->trace(EmissionAim{true, radius});
        missed = cache.pathsMissingScene();
        wasted = 0;
        std::vector<Segment> firstMisses, path;
        for (size_t p = 0; p < cache.pathCount(); ++p) {
            path.clear();
            cache.appendPath(p, path);
            if (path.empty()) {  // a spot light's photon outside its cone
                ++wasted;
                continue;
            }
            if (!path.front().hasImpact()) firstMisses.push_back(path.front());
        }
        std::vector<SegmentCrossing> crossings;
        discs.findCrossings(firstMisses, DetpDiscs::Discs::All, crossings);
        std::vector<uint8_t> crosses(firstMisses.size(), 0);
        for (const SegmentCrossing& c : crossings) crosses[c.segment] = 1;
        wasted += uint64_t(std::count(crosses.begin(), crosses.end(), uint8_t(0)));
    }
    state.counters["missed_fraction"] = double(missed) / double(f->kPhotons);
    state.counters["wasted_fraction"] = double(wasted) / double(f->kPhotons);
}

}  // namespace

BENCHMARK(BM_FlightHelmetEmission)->Args({0, 0})->Args({1, 0})->Args({1, 13})->ArgNames({"aim", "margin_mm"})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FlightHelmetDetpWaste)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_TracePhotons)
    ->ArgNames({"photons", "random"})
    ->ArgsProduct({{100000, 1000000, 10000000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DecodeRayCache)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EmbreeClosestHitCeiling)->Arg(100000)->Arg(1000000)->Arg(10000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DetpSegments)->ArgsProduct({{100000, 1000000}, {20, 50}, {0, 1}})->ArgNames({"photons", "radius_mm", "decode"})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EmbreeAllHitsCeiling)->ArgsProduct({{100000, 1000000}, {20, 50}})->ArgNames({"photons", "radius_mm"})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DiscRegions)->ArgsProduct({{20, 50, 100}, {0, 1}})->ArgNames({"radius_mm", "coverage"})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Estimate)->Apply(estimatorArguments)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

BENCHMARK_MAIN();
