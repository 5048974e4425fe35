// How reading inputs grows with their size (issue 23): a node hierarchy nested 10^3…10^5 deep, a
// transform file keying 10^3…10^5 frames, and the aimed-emission set-up for 10…10^4 point lights
// beside the same set-up unaimed. Each size is timed on its own; Google Benchmark's complexity
// fit (BigO, RMS) says whether the growth is linear. Speed is measured here, never asserted in
// ctest. Run: scripts/bench.sh --benchmark_filter='Chain|Keyed|Lights'.
#include <benchmark/benchmark.h>

#include <nlohmann/json.hpp>

#include <random>
#include <string>

#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "trace/light_sampler.h"

using namespace qsgi;
using json = nlohmann::json;

namespace {

// A 2 m floor quad (embedded buffer) hanging from `depth` nested nodes, each 1e-6 up from its
// parent, and `lights` point lights scattered above it (one node each), as a .gltf in memory.
std::string floorScene(int depth, int lights) {
    // Positions (4 × VEC3 float) then indices (6 × uint16), base64 of the 60 bytes.
    static const char* kData =
        "data:application/octet-stream;base64,AACAvwAAAAAAAIA/AACAPwAAAAAAAIA/AACAPwAAAAAAAIC/AACAvwAAAAAAAIC/AAABAAIAAAACAAMA";
    json doc = {{"asset", {{"version", "2.0"}}},
                {"scene", 0},
                {"buffers", {{{"byteLength", 60}, {"uri", kData}}}},
                {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
                                 {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 12}}}},
                {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"},
                                {"min", {-1, 0, -1}}, {"max", {1, 0, 1}}},
                               {{"bufferView", 1}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
                {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
                {"extensionsUsed", {"KHR_lights_punctual"}}};
    json nodes = json::array(), roots = json::array(), lightList = json::array();
    // nodes[0 … depth-1]: the chain; the floor hangs from its last link.
    for (int i = 0; i < depth; ++i)
        nodes.push_back({{"translation", {0, 1e-6, 0}}, {"children", {i + 1}}});
    nodes.push_back({{"name", "Floor"}, {"mesh", 0}});
    roots.push_back(0);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> across(-1, 1), up(0.2, 2);
    for (int l = 0; l < lights; ++l) {
        lightList.push_back({{"type", "point"}, {"intensity", 10.0 / lights}});
        roots.push_back(int(nodes.size()));
        nodes.push_back({{"translation", {across(random), up(random), across(random)}},
                         {"extensions", {{"KHR_lights_punctual", {{"light", l}}}}}});
    }
    doc["nodes"] = nodes;
    doc["scenes"] = {{{"nodes", roots}}};
    doc["extensions"] = {{"KHR_lights_punctual", {{"lights", lightList}}}};
    return doc.dump();
}

Scene load(const std::string& gltf) {
    Warnings warnings;
    return loadGltfSceneFromMemory("bench.gltf", gltf, ".", warnings);
}

void BM_LoadNodeChain(benchmark::State& state) {
    const std::string gltf = floorScene(int(state.range(0)), 1);
    for (auto _ : state) benchmark::DoNotOptimize(load(gltf).nodes.size());
    state.SetComplexityN(state.range(0));
}

void BM_ParseKeyedFrames(benchmark::State& state) {
    const Scene scene = load(floorScene(1, 1));
    json frames = json::array();
    for (int f = 0; f < state.range(0); ++f)
        frames.push_back({{"frame", f}, {"nodes", {{"Floor", {{"translation", {0.001 * f, 0, 0}}}}}}});
    const json doc = {{"format", "qsgi-animation"}, {"version", 1}, {"frames", frames}};
    for (auto _ : state) benchmark::DoNotOptimize(Animation::parseTransformFile("bench.json", doc, scene).lastFrame());
    state.SetComplexityN(state.range(0));
}

// The light sampler's set-up, aimed (range(1) = 1: a projection map per light) or not.
void BM_LightsSetUp(benchmark::State& state) {
    const Scene scene = load(floorScene(1, int(state.range(0))));
    const EmissionAim aim{state.range(1) != 0, 0.0f};
    for (auto _ : state) {
        const LightSampler sampler(scene, 1000000, 1e-5f, aim);
        benchmark::DoNotOptimize(sampler.emittedFraction());
    }
}

}  // namespace

BENCHMARK(BM_LoadNodeChain)->RangeMultiplier(10)->Range(1000, 100000)->Complexity(benchmark::oN)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ParseKeyedFrames)->RangeMultiplier(10)->Range(1000, 100000)->Complexity(benchmark::oN)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LightsSetUp)->ArgsProduct({{10, 100, 1000, 10000}, {0, 1}})->ArgNames({"lights", "aim"})
    ->Unit(benchmark::kMillisecond)->UseRealTime();
