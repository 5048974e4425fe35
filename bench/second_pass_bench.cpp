// The second pass's rays beside Embree's own pace (issue 45): a scene's final-gather rays — every
// vertex's M cosine-distributed rays from its start point s_v, as FinalGather casts them: the same
// origins and directions, tnear 0, tfar ∞, in vertex order — traced five ways in one run:
//   gather     FinalGather::castAll itself (directions made, hits kept: what a frame pays);
//   streamed   FinalGather::castAndGather (hits summed as cast, none kept: the last frame's way);
//   scene_bvh  SceneBvh::intersect on the prepared rays (our tracing alone: static and dynamic
//              parts, robust, the tie filter);
//   ceiling    Embree configured as SceneBvh configures it (robust, tie filter) on one scene
//              holding every triangle, rtcIntersect1: BM_EmbreeClosestHitCeiling's configuration;
//   robust1    the same scene with the robust flag and no filter, rtcIntersect1 (what the tie
//              filter costs: ceiling against this; what robust traversal costs: this against raw1);
//   raw1       one scene, build quality high, no robust flag, no filter, rtcIntersect1;
//   raw16      the same, rtcIntersect16, each packet 16 consecutive rays of one vertex (coherent).
// Every form runs on all cores over the same rays; rays_per_s is the counter to read, and a form's
// share of the hardware's pace is its rate over the faster raw one's. Scenes: data/cornell (an
// area light in a box), data/cornell refined to 2.5 cm (a dense single mesh, 90,828 vertices),
// the dense floor cropped to 8 x 8 tiles (out/bench/scenes, made by scripts/bench.sh), and
// ../shared's 2CylinderEngine (open: most rays escape, as under a sky) and FlightHelmet (a real
// asset: low-poly, smooth-shaded, overlapping parts). Skipped, saying why, where a scene's file is
// absent.
//
// BM_VertexStarts: where those rays start (VertexStarts::computeAll, issue 56), per vertex, on the
// same scenes; its vertices_per_s against the gather form's rays_per_s / 64 tells what a start
// costs in gather rays.
#include <benchmark/benchmark.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <memory>

#include "embree_scenes.h"
#include "estimate/final_gather.h"
#include "estimate/vertex_starts.h"
#include "scene/gltf_loader.h"
#include "scene/mesh_refinement.h"

using namespace qsgi;

namespace {

constexpr uint32_t kRaysPerVertex = 64;

enum RayScene { kCornell = 0, kCornellRefined = 1, kDenseFloor = 2, kEngine = 3, kHelmet = 4 };
const char* kSceneNames[] = {"cornell", "cornell refined 0.025", "dense floor 8x8 tiles", "2CylinderEngine", "FlightHelmet"};
const char* kScenePaths[] = {QSGI_SOURCE_DIR "/data/cornell/cornell.gltf", QSGI_SOURCE_DIR "/data/cornell/cornell.gltf",
                             QSGI_SOURCE_DIR "/out/bench/scenes/dense-floor-8/dense-floor-8.gltf",
                             QSGI_SOURCE_DIR "/../shared/data/gltf-samples/valid/2CylinderEngine/2CylinderEngine.glb",
                             QSGI_SOURCE_DIR "/../shared/data/gltf-samples/models/FlightHelmet/glTF/FlightHelmet.gltf"};

// A scene, its start points and its gather rays, made once per process and scene.
struct GatherRays {
    Scene scene;
    EmbreeDevice device;
    std::unique_ptr<SceneBvh> bvh;
    VertexStarts starts;
    std::unique_ptr<FinalGather> gather;
    std::vector<Vec3f> origins, directions;  // vertex-major, kRaysPerVertex each (hidden vertices: none)

    explicit GatherRays(RayScene which) {
        Warnings w;
        scene = loadGltfScene(kScenePaths[which], w);
        if (which == kCornellRefined) refineMesh(scene, 0.025);
        bvh = std::make_unique<SceneBvh>(device, scene);
        starts.computeAll(scene, *bvh);
        gather = std::make_unique<FinalGather>(kRaysPerVertex, 1);
        gather->castAll(scene, *bvh, starts);
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            if (scene.vertexHidden[v]) continue;
            for (uint32_t j = 0; j < kRaysPerVertex; ++j) {
                origins.push_back(starts.point(v));
                directions.push_back(FinalGather::rayDirection(gather->hit(v, j)));
            }
        }
    }
};

GatherRays* gatherRays(benchmark::State& state) {
    static std::map<int, std::unique_ptr<GatherRays>> made;
    const auto which = RayScene(state.range(0));
    if (!std::ifstream(kScenePaths[which])) {
        state.SkipWithError((std::string(kScenePaths[which]) + " is absent (scripts/bench.sh makes out/bench/scenes; ../shared "
                                                                "sits beside the repository)")
                                .c_str());
        return nullptr;
    }
    auto& g = made[int(which)];
    // (made once per scene and process: the first run of a scene pays for it, outside the timing)
    if (!g) g = std::make_unique<GatherRays>(which);
    return g.get();
}

RTCRayHit makeRayHit(const Vec3f& o, const Vec3f& d) {
    RTCRayHit rh{};
    rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
    rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::numeric_limits<float>::infinity();
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

// Counts the rays that hit, over [0, rays) in chunks of 16 (so that packets never straddle two
// vertices: kRaysPerVertex is a multiple of 16), on all cores.
size_t overRays(size_t rays, const std::function<size_t(size_t, size_t)>& traceChunk) {
    return tbb::parallel_reduce(
        tbb::blocked_range<size_t>(0, rays / 16, 64), size_t(0),
        [&](const tbb::blocked_range<size_t>& r, size_t count) {
            for (size_t chunk = r.begin(); chunk < r.end(); ++chunk) count += traceChunk(16 * chunk, 16 * chunk + 16);
            return count;
        },
        std::plus<size_t>());
}

enum Form { kGather = 0, kSceneBvh = 1, kCeiling = 2, kRaw1 = 3, kRaw16 = 4, kStreamed = 5, kRobust1 = 6 };
const char* kFormNames[] = {"gather", "scene_bvh", "ceiling", "raw1", "raw16", "streamed", "robust1"};

void BM_GatherRays(benchmark::State& state) {
    GatherRays* g = gatherRays(state);
    if (!g) return;
    const auto form = Form(state.range(1));
    const size_t rays = g->origins.size();
    std::unique_ptr<WholeEmbreeScene> whole;
    if (form == kCeiling) whole = std::make_unique<WholeEmbreeScene>(g->device, g->scene, WholeEmbreeScene::Config::AsSceneBvh);
    if (form == kRobust1) whole = std::make_unique<WholeEmbreeScene>(g->device, g->scene, WholeEmbreeScene::Config::RobustOnly);
    if (form == kRaw1 || form == kRaw16) whole = std::make_unique<WholeEmbreeScene>(g->device, g->scene, WholeEmbreeScene::Config::Raw);
    size_t hits = 0;
    std::vector<Vec3f> firstPass(g->scene.vertexCount(), Vec3f(0.5f)), gathered;
    for (auto _ : state) {
        switch (form) {
            case kStreamed: {
                FinalGather streamed(kRaysPerVertex, 1);
                const std::vector<uint8_t> none;
                streamed.castAndGather(g->scene, *g->bvh, g->starts, FinalGather::FirstPass{firstPass, firstPass, none}, gathered);
                hits = rays;
                break;
            }
            case kGather:
                g->gather->castAll(g->scene, *g->bvh, g->starts);
                hits = rays;
                break;
            case kSceneBvh:
                hits = overRays(rays, [&](size_t begin, size_t end) {
                    size_t n = 0;
                    for (size_t i = begin; i < end; ++i)
                        n += g->bvh->intersect(g->origins[i], g->directions[i], 0.0f, std::numeric_limits<float>::infinity()).has_value();
                    return n;
                });
                break;
            case kCeiling:
            case kRobust1:
            case kRaw1:
                hits = overRays(rays, [&](size_t begin, size_t end) {
                    size_t n = 0;
                    for (size_t i = begin; i < end; ++i) {
                        RTCRayHit rh = makeRayHit(g->origins[i], g->directions[i]);
                        TieBreakContext context;  // its fields are read by the ceiling's filter only
                        rtcInitIntersectContext(&context.base);
                        rtcIntersect1(whole->get(), &context.base, &rh);
                        n += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
                    }
                    return n;
                });
                break;
            case kRaw16:
                hits = overRays(rays, [&](size_t begin, size_t) {
                    RTCRayHit16 packet;
                    alignas(64) int valid[16];
                    for (size_t k = 0; k < 16; ++k) {
                        const RTCRayHit one = makeRayHit(g->origins[begin + k], g->directions[begin + k]);
                        valid[k] = -1;
                        packet.ray.org_x[k] = one.ray.org_x, packet.ray.org_y[k] = one.ray.org_y, packet.ray.org_z[k] = one.ray.org_z;
                        packet.ray.dir_x[k] = one.ray.dir_x, packet.ray.dir_y[k] = one.ray.dir_y, packet.ray.dir_z[k] = one.ray.dir_z;
                        packet.ray.tnear[k] = one.ray.tnear, packet.ray.tfar[k] = one.ray.tfar;
                        packet.ray.time[k] = 0, packet.ray.mask[k] = ~0u, packet.ray.id[k] = unsigned(k), packet.ray.flags[k] = 0;
                        packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    }
                    RTCIntersectContext context;
                    rtcInitIntersectContext(&context);
                    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
                    rtcIntersect16(valid, whole->get(), &context, &packet);
                    size_t n = 0;
                    for (size_t k = 0; k < 16; ++k) n += packet.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
                    return n;
                });
                break;
        }
        benchmark::DoNotOptimize(hits);
    }
    state.counters["rays_per_s"] = benchmark::Counter(double(rays), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["hit_share"] = double(hits) / double(rays);
    state.counters["vertices"] = double(g->scene.vertexCount());
    state.SetLabel(std::string(kSceneNames[state.range(0)]) + ", " + kFormNames[form]);
}

void BM_VertexStarts(benchmark::State& state) {
    GatherRays* g = gatherRays(state);
    if (!g) return;
    VertexStarts starts;
    for (auto _ : state) {
        starts.computeAll(g->scene, *g->bvh);
        benchmark::DoNotOptimize(starts.point(0));
    }
    state.counters["vertices_per_s"] = benchmark::Counter(double(g->scene.vertexCount()), benchmark::Counter::kIsIterationInvariantRate);
    state.counters["vertices"] = double(g->scene.vertexCount());
    state.SetLabel(kSceneNames[state.range(0)]);
}

}  // namespace

BENCHMARK(BM_VertexStarts)
    ->ArgsProduct({{kCornell, kCornellRefined, kDenseFloor, kEngine, kHelmet}})
    ->ArgNames({"scene"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_GatherRays)
    ->ArgsProduct({{kCornell, kCornellRefined, kDenseFloor, kEngine, kHelmet}, {kGather, kStreamed, kSceneBvh, kCeiling, kRobust1, kRaw1, kRaw16}})
    ->ArgNames({"scene", "form"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
