// Density-estimation benchmarks on data/cornell (issue 4): each estimator at 10^5 and 10^6
// photons and r in {0.02, 0.05, 0.1}: indexed vs brute force (10^5 only: brute force at 10^6
// takes minutes), sorted vs unsorted queries, and DETP's FLANN candidates vs the exact index with
// the approximation's error; DETP's boundary rules (clip, linear, paper) and the cost of the disc
// regions they need (per radius, with and without the photon map's coverage probes). Photon
// tracing throughput too. Counters carry the work done, so
// ratios can be read within one run.
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "estimate/accuracy.h"
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
        if (!c) c = std::make_unique<RayCache>(PhotonTracer(scene, *bvh, TraceSettings{photons, 1, 32}).traceAll());
        return *c;
    }
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
    s.k = 50;
    s.useIndex = mode != kBruteForce;
    s.sortQueries = mode != kIndexedUnsorted;
    s.detpIndex = mode == kFlannCandidates ? DetpIndex::Flann : DetpIndex::Embree;
    s.boundary = rule;
    // Regions are made once (BM_DiscRegions times them): this measures the estimate alone.
    const DiscRegions* regions = needsDiscRegions(s) ? &f.discRegions(radiusMm, kind == EstimatorKind::PhotonMap) : nullptr;
    VertexRadiosity result;
    for (auto _ : state) {
        result = estimateVertexRadiosity(f.scene, *f.bvh, cache, s, f.device, regions);
        benchmark::DoNotOptimize(result.irradiance.data());
    }
    state.counters["segments"] = double(cache.segments.size());
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
    SceneBvh bvh(f.device, f.scene);
    const PhotonTracer tracer(f.scene, bvh, TraceSettings{photons, 1, 32});
    size_t segments = 0;
    for (auto _ : state) {
        const RayCache cache = tracer.traceAll();
        segments = cache.segments.size();
    }
    state.counters["segments_per_s"] = benchmark::Counter(double(segments), benchmark::Counter::kIsIterationInvariantRate);
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

}  // namespace

BENCHMARK(BM_TracePhotons)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_DiscRegions)->ArgsProduct({{20, 50, 100}, {0, 1}})->ArgNames({"radius_mm", "coverage"})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Estimate)->Apply(estimatorArguments)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

BENCHMARK_MAIN();
