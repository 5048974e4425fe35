// Density-estimation benchmarks on data/cornell (issue 4): each estimator at 10^5 and 10^6
// photons and r in {0.02, 0.05, 0.1}: indexed vs brute force (10^5 only: brute force at 10^6
// takes minutes), sorted vs unsorted queries, and DETP's FLANN candidates vs the exact index with
// the approximation's error. Photon tracing throughput too. Counters carry the work done, so
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
    std::map<uint64_t, std::unique_ptr<RayCache>> caches;
    std::map<std::pair<uint64_t, int>, std::vector<Vec3f>> exactDetp;

    CornellFixture() {
        Warnings w;
        scene = loadGltfScene(QSGI_SOURCE_DIR "/data/cornell/cornell.gltf", w);
    }
    const RayCache& cache(uint64_t photons) {
        auto& c = caches[photons];
        if (!c) {
            SceneBvh bvh(device, scene);
            c = std::make_unique<RayCache>(PhotonTracer(scene, bvh, TraceSettings{photons, 1, 32}).traceAll());
        }
        return *c;
    }
    const std::vector<Vec3f>& exact(uint64_t photons, int radiusMm) {
        auto& e = exactDetp[{photons, radiusMm}];
        if (e.empty()) {
            EstimatorSettings s;
            s.kind = EstimatorKind::Detp;
            s.radius = radiusMm / 1000.0f;
            e = estimateVertexRadiosity(scene, cache(photons), s, device).irradiance;
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
    CornellFixture& f = fixture();
    const RayCache& cache = f.cache(photons);
    EstimatorSettings s;
    s.kind = kind;
    s.radius = radiusMm / 1000.0f;
    s.k = 50;
    s.useIndex = mode != kBruteForce;
    s.sortQueries = mode != kIndexedUnsorted;
    s.detpIndex = mode == kFlannCandidates ? DetpIndex::Flann : DetpIndex::Embree;
    VertexRadiosity result;
    for (auto _ : state) {
        result = estimateVertexRadiosity(f.scene, cache, s, f.device);
        benchmark::DoNotOptimize(result.irradiance.data());
    }
    state.counters["segments"] = double(cache.segments.size());
    if (kind == EstimatorKind::Detp && mode == kFlannCandidates) {
        const ErrorStats e = errorStats(result.irradiance, f.exact(photons, radiusMm));
        state.counters["rel_rms_vs_exact"] = e.relativeRms;
        state.counters["rel_bias_vs_exact"] = e.relativeBias;
    }
    static const char* modes[] = {"indexed+sorted", "indexed+unsorted", "brute-force", "flann-candidates"};
    state.SetLabel(std::string(estimatorName(kind)) + " " + modes[mode]);
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
    for (int64_t photons : {100000, 1000000}) {
        b->Args({int64_t(EstimatorKind::ImpactCount), photons, 0, kIndexedSorted});
        for (int64_t radius : {20, 50, 100}) {
            for (int64_t kind : {int64_t(EstimatorKind::PhotonMap), int64_t(EstimatorKind::Detp)}) {
                b->Args({kind, photons, radius, kIndexedSorted});
                b->Args({kind, photons, radius, kIndexedUnsorted});
                if (photons == 100000) b->Args({kind, photons, radius, kBruteForce});
            }
            b->Args({int64_t(EstimatorKind::Detp), photons, radius, kFlannCandidates});
        }
    }
    b->ArgNames({"estimator", "photons", "radius_mm", "mode"});
}

}  // namespace

BENCHMARK(BM_TracePhotons)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Estimate)->Apply(estimatorArguments)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

BENCHMARK_MAIN();
