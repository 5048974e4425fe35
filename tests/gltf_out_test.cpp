// --gltf-out (issue 35): asset.glb is the scene's own glTF file with the bake added. Checked with
// tools independent of qsgi (scripts/gltf-check/check.mjs: the Khronos glTF-Validator and glTF
// Transform's reader, installed by scripts/setup.sh --test):
//   - the validator reports no error code the input lacked;
//   - the JSON equals the input's in every object once the added attributes, targets, weights,
//     channels, samplers, accessors, views, mesh copies and the packed buffers are taken out;
//   - every target the asset gains has a POSITION of zeros taking no bytes (issue 46: Blender
//     makes shape keys only of targets with POSITION), the input's own targets left as they were;
//   - glTF Transform, evaluating the morph targets under the file's weights animation at each
//     frame's time, gets every frame's _RADIANCE = B/π and _IRRADIANCE = E of the frame's PLY back
//     within float rounding, and COLOR_n = min(1, exposure · B/π);
//   - a transform file's motion, played back from the asset by qsgi's glTF reader, gives the
//     transform file's poses; the bytes are the same for any thread count.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <regex>
#include <set>

#include "output/ply_reader.h"
#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "scene/keyframes.h"
#include "test_support.h"

using namespace qsgi;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

// The checkers are a test dependency (scripts/setup.sh --test installs them), so their absence
// fails the tests rather than skipping them: a skip would let CI pass without checking a file.
std::string checkerCommand(const fs::path& file, const std::string& options) {
    const fs::path tool = sourceDir() / "scripts/gltf-check";
    if (!fs::exists(tool / "node_modules/gltf-validator"))
        throw std::runtime_error("the glTF checkers are not installed: run scripts/setup.sh (npm ci in " +
                                 tool.string() + ")");
    return "node " + (tool / "check.mjs").string() + options + " " + file.string();
}

json runChecker(const fs::path& file, const std::string& option) {
    const CommandResult r = runCommand(checkerCommand(file, " " + option));
    if (r.exitCode != 0) throw std::runtime_error("check.mjs failed on " + file.string() + ": " + r.output.substr(0, 2000));
    // runCommand adds stderr to the output, but check.mjs writes there only when it fails.
    return json::parse(r.output);
}

// The validator's error codes (of its first 100 messages, "SEVERITY CODE POINTER: TEXT", 0 an error).
std::set<std::string> errorCodes(const json& report) {
    std::set<std::string> codes;
    for (const json& m : report["validator"]["messages"]) {
        const std::string text = m.get<std::string>();
        if (text.rfind("0 ", 0) == 0) codes.insert(text.substr(2, text.find(' ', 2) - 2));
    }
    return codes;
}

// The JSON of a .gltf or of a .glb's JSON chunk.
json documentJson(const fs::path& file) {
    const std::string bytes = readFileBytes(file);
    if (bytes.compare(0, 4, "glTF") != 0) return json::parse(bytes);
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return json::parse(bytes.substr(20, length));
}

std::string frameName(int frame, const char* extension) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.%s", frame, extension);
    return name;
}

// Every target qsgi appended to `mesh` (after the `original`'s own) holds POSITION: zeros with no
// view, float VEC3 of the primitive's vertex count, bounds 0, so that Blender's importer makes a
// shape key of it and nothing moves. A primitive without POSITION gets none (the validator's
// MESH_PRIMITIVE_MORPH_TARGET_NO_BASE_ACCESSOR). `accessors`: the asset's.
void expectAddedTargetsHoldZeroPositions(const json& mesh, const json& original, const json& accessors) {
    for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
        SCOPED_TRACE("primitive " + std::to_string(p));
        const json& primitive = mesh["primitives"][p];
        const json& before = original["primitives"][p];
        const size_t own = before.contains("targets") ? before["targets"].size() : 0;
        if (!primitive.contains("targets")) continue;
        const bool positioned = primitive["attributes"].contains("POSITION");
        const json vertices = positioned ? accessors.at(primitive["attributes"]["POSITION"].get<size_t>())["count"] : json();
        for (size_t t = own; t < primitive["targets"].size(); ++t) {
            const json& target = primitive["targets"][t];
            if (!positioned) {
                EXPECT_FALSE(target.contains("POSITION")) << "targets[" << t << "]";
                continue;
            }
            if (!target.contains("POSITION")) {
                ADD_FAILURE() << "targets[" << t << "] has no POSITION: " << target.dump();
                continue;
            }
            const json& a = accessors.at(target["POSITION"].get<size_t>());
            EXPECT_FALSE(a.contains("bufferView")) << a.dump();
            EXPECT_FALSE(a.contains("sparse")) << a.dump();
            EXPECT_EQ(a.value("componentType", 0), 5126) << a.dump();
            EXPECT_EQ(a.value("type", ""), "VEC3") << a.dump();
            EXPECT_EQ(a["count"], vertices) << a.dump();
            EXPECT_EQ(a.value("min", json()), json::array({0, 0, 0})) << a.dump();
            EXPECT_EQ(a.value("max", json()), json::array({0, 0, 0})) << a.dump();
        }
    }
}

// Takes out of `out` what --gltf-out adds to `in` and checks, as it goes, that the added parts
// are where they belong; what is left must equal `in`. `colourSet` is --gltf-colour's (-1: none).
// With `refined` (--subdivide), a primitive's attributes, indices and targets are new accessors of
// the refined mesh: only their names are compared here (the values by loading the asset).
json withoutTheBake(json out, const json& in, int colourSet, bool refined = false) {
    // One buffer; the input's views keep their order and lengths (their buffer and offset move);
    // accessors are appended, never edited.
    EXPECT_EQ(out["buffers"].size(), 1u);
    EXPECT_FALSE(out["buffers"][0].contains("uri"));
    out["buffers"] = in["buffers"];
    for (size_t v = 0; v < in["bufferViews"].size(); ++v) {
        json view = out["bufferViews"][v], original = in["bufferViews"][v];
        for (json* j : {&view, &original}) {
            j->erase("buffer");
            j->erase("byteOffset");
        }
        EXPECT_EQ(view, original) << "bufferViews[" << v << "]";
    }
    out["bufferViews"] = in["bufferViews"];
    for (size_t a = 0; a < in["accessors"].size(); ++a) EXPECT_EQ(out["accessors"][a], in["accessors"][a]) << "accessors[" << a << "]";
    const json accessors = out["accessors"];
    out["accessors"] = in["accessors"];
    // An image's file becomes a view of its bytes.
    if (in.contains("images"))
        for (size_t i = 0; i < in["images"].size(); ++i)
            if (in["images"][i].contains("uri")) {
                EXPECT_TRUE(out["images"][i].contains("bufferView")) << "images[" << i << "]";
                EXPECT_TRUE(out["images"][i].contains("mimeType")) << "images[" << i << "]";
                out["images"][i] = in["images"][i];
            }
    // Each primitive gains _RADIANCE, _IRRADIANCE (and COLOR_n); targets and weights are appended.
    auto strip = [&](json mesh, const json& original) {
        for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
            json& primitive = mesh["primitives"][p];
            const json& before = original["primitives"][p];
            std::vector<std::string> added = {"_RADIANCE", "_IRRADIANCE"};
            if (colourSet >= 0) added.push_back("COLOR_" + std::to_string(colourSet));
            // A doubleSided material's primitive also carries its back side's values.
            const bool twoSided = before.contains("material") && in.contains("materials") &&
                                  in["materials"][before["material"].get<size_t>()].value("doubleSided", false);
            if (twoSided) added.insert(added.end(), {"_BACK_RADIANCE", "_BACK_IRRADIANCE"});
            for (const std::string& name : added) {
                EXPECT_TRUE(primitive["attributes"].contains(name)) << name;
                primitive["attributes"].erase(name);
            }
            if (before.contains("targets")) primitive["targets"].erase(primitive["targets"].begin() + std::ptrdiff_t(before["targets"].size()), primitive["targets"].end());
            else primitive.erase("targets");
            if (refined) {
                for (const char* part : {"attributes", "indices"}) {
                    if (!before.contains(part)) continue;
                    if (before[part].is_object()) {
                        for (const auto& [name, index] : before[part].items()) EXPECT_TRUE(primitive[part].contains(name)) << name;
                    }
                    primitive[part] = before[part];
                }
                if (before.contains("targets")) primitive["targets"] = before["targets"];
                if (before.contains("mode")) primitive["mode"] = before["mode"];
            }
        }
        if (original.contains("weights")) mesh["weights"].erase(mesh["weights"].begin() + std::ptrdiff_t(original["weights"].size()), mesh["weights"].end());
        return mesh;
    };
    const size_t meshes = in["meshes"].size();
    std::vector<size_t> copyOf;  // of out's meshes beyond the input's
    for (size_t m = 0; m < out["meshes"].size(); ++m) {
        if (m < meshes) {
            expectAddedTargetsHoldZeroPositions(out["meshes"][m], in["meshes"][m], accessors);
            out["meshes"][m] = strip(out["meshes"][m], in["meshes"][m]);
            continue;
        }
        // A copy for nodes whose bakes differ: equal to one of the input's meshes.
        size_t found = meshes;
        for (size_t i = 0; i < meshes && found == meshes; ++i)
            if (out["meshes"][m]["primitives"].size() == in["meshes"][i]["primitives"].size() && strip(out["meshes"][m], in["meshes"][i]) == in["meshes"][i])
                found = i;
        EXPECT_LT(found, meshes) << "meshes[" << m << "] is no copy of an input mesh";
        if (found < meshes) expectAddedTargetsHoldZeroPositions(out["meshes"][m], in["meshes"][found], accessors);
        copyOf.push_back(found);
    }
    out["meshes"].erase(out["meshes"].begin() + std::ptrdiff_t(meshes), out["meshes"].end());
    for (size_t n = 0; n < out["nodes"].size(); ++n) {
        json& node = out["nodes"][n];
        if (node.contains("mesh") && node["mesh"].get<size_t>() >= meshes) node["mesh"] = copyOf.at(node["mesh"].get<size_t>() - meshes);
        const json& original = in["nodes"][n];
        if (original.contains("weights")) node["weights"].erase(node["weights"].begin() + std::ptrdiff_t(original["weights"].size()), node["weights"].end());
    }
    // Animations keep their channels and samplers; a channel may point at a new sampler (its
    // output extended), new channels and samplers are appended, and a new animation may follow.
    const size_t animations = in.contains("animations") ? in["animations"].size() : 0;
    if (out.contains("animations")) {
        for (size_t a = 0; a < animations; ++a) {
            json& animation = out["animations"][a];
            const json& original = in["animations"][a];
            const size_t channels = original["channels"].size(), samplers = original["samplers"].size();
            for (size_t c = 0; c < channels; ++c) animation["channels"][c]["sampler"] = original["channels"][c]["sampler"];
            animation["channels"].erase(animation["channels"].begin() + std::ptrdiff_t(channels), animation["channels"].end());
            animation["samplers"].erase(animation["samplers"].begin() + std::ptrdiff_t(samplers), animation["samplers"].end());
        }
        out["animations"].erase(out["animations"].begin() + std::ptrdiff_t(animations), out["animations"].end());
        if (animations == 0) out.erase("animations");
    }
    // The bake's description.
    EXPECT_TRUE(out["extras"].contains("qsgi"));
    out["extras"].erase("qsgi");
    if (out["extras"].empty() && !in.contains("extras")) out.erase("extras");
    return out;
}

// The scene vertices of (node, primitive), as the loader placed them.
struct Block {
    uint32_t first = 0, count = 0;
};
std::map<std::pair<int, int>, Block> vertexBlocks(const fs::path& scene) {
    Warnings w;
    const Scene s = loadGltfScene(scene.string(), w);
    std::map<std::pair<int, int>, Block> blocks;
    for (const MeshInstance& i : s.instances) blocks[{i.node, i.primitive}] = Block{i.firstVertex, i.vertexCount};
    return blocks;
}

// Every frame's baked values, as glTF Transform evaluates the asset's morph targets at the frame's
// time in `animation`, against the frame's PLY. Returns how many values were compared.
size_t expectFramesReadBack(const fs::path& scene, const fs::path& folder, int firstFrame, int lastFrame, double fps,
                            const std::string& animation, int colourSet) {
    const json frames = runChecker(folder / "asset.glb", "--frames");
    const json asset = documentJson(folder / "asset.glb");
    const double exposure = asset["extras"]["qsgi"]["exposure"].get<double>();
    const auto blocks = vertexBlocks(scene);
    const auto played = std::find_if(frames["animations"].begin(), frames["animations"].end(),
                                     [&](const json& a) { return a["name"] == animation; });
    if (played == frames["animations"].end()) {
        ADD_FAILURE() << "no animation '" << animation << "' drives the lighting: " << frames.dump().substr(0, 400);
        return 0;
    }
    const std::vector<double> times = (*played)["times"].get<std::vector<double>>();
    const VertexRadiosityPly first = readVertexRadiosityPly((folder / frameName(firstFrame, "ply")).string());
    size_t compared = 0;
    double worst = 0;
    for (int frame = firstFrame; frame <= lastFrame; ++frame) {
        SCOPED_TRACE("frame " + std::to_string(frame));
        const VertexRadiosityPly ply = readVertexRadiosityPly((folder / frameName(frame, "ply")).string());
        const double t = double(float(frame / fps));
        const auto at = std::find(times.begin(), times.end(), t);
        if (at == times.end()) {
            ADD_FAILURE() << "no key at the frame's time " << t;
            continue;
        }
        const size_t k = size_t(at - times.begin());
        std::set<std::pair<int, int>> seen;
        for (const json& node : (*played)["nodes"])
            for (const json& primitive : node["primitives"]) {
                const std::pair<int, int> key{node["node"].get<int>(), primitive["primitive"].get<int>()};
                const auto block = blocks.find(key);
                if (block == blocks.end()) continue;  // not rendered: zeros by definition
                seen.insert(key);
                const json& attributes = primitive["attributes"];
                const std::vector<double> radiance = attributes["_RADIANCE"][k].get<std::vector<double>>();
                const std::vector<double> irradiance = attributes["_IRRADIANCE"][k].get<std::vector<double>>();
                std::vector<double> colour, backRadiance, backIrradiance;
                if (colourSet >= 0) colour = attributes["COLOR_" + std::to_string(colourSet)][k].get<std::vector<double>>();
                const bool back = attributes.contains("_BACK_RADIANCE");
                if (back) {
                    backRadiance = attributes["_BACK_RADIANCE"][k].get<std::vector<double>>();
                    backIrradiance = attributes["_BACK_IRRADIANCE"][k].get<std::vector<double>>();
                    EXPECT_EQ(backRadiance.size(), radiance.size());
                    EXPECT_EQ(ply.backRadiosity.size(), ply.radiosity.size()) << "the PLY has no back columns";
                }
                EXPECT_EQ(radiance.size(), 3 * size_t(block->second.count));
                for (uint32_t v = 0; v < block->second.count && 3 * v + 2 < radiance.size(); ++v)
                    for (int c = 0; c < 3; ++c) {
                        const size_t i = block->second.first + v;
                        // Float rounding of B/π, of the delta from frame 0 and of their sum.
                        const double b = double(ply.radiosity[i][c]) / M_PI, b0 = double(first.radiosity[i][c]) / M_PI;
                        const double e = ply.irradiance[i][c], e0 = first.irradiance[i][c];
                        const double got = radiance[3 * v + size_t(c)], gotE = irradiance[3 * v + size_t(c)];
                        EXPECT_LE(std::fabs(got - b), 0x1p-21 * (std::fabs(b) + std::fabs(b0)) + 1e-35) << "vertex " << i;
                        EXPECT_LE(std::fabs(gotE - e), 0x1p-21 * (std::fabs(e) + std::fabs(e0)) + 1e-35) << "vertex " << i;
                        worst = std::max(worst, std::fabs(got - b) / std::max(std::fabs(b) + std::fabs(b0), 1e-30));
                        if (colourSet >= 0) {
                            const double expected = std::min(1.0, exposure * double(float(ply.radiosity[i][c] * float(1 / M_PI))));
                            EXPECT_NEAR(colour[3 * v + size_t(c)], expected, 1e-6) << "vertex " << i;
                        }
                        compared += 2;
                        if (back && 3 * v + 2 < backRadiance.size() && i < ply.backRadiosity.size()) {
                            const double bb = double(ply.backRadiosity[i][c]) / M_PI, bb0 = double(first.backRadiosity[i][c]) / M_PI;
                            const double be = ply.backIrradiance[i][c], be0 = first.backIrradiance[i][c];
                            EXPECT_LE(std::fabs(backRadiance[3 * v + size_t(c)] - bb), 0x1p-21 * (std::fabs(bb) + std::fabs(bb0)) + 1e-35)
                                << "back of vertex " << i;
                            EXPECT_LE(std::fabs(backIrradiance[3 * v + size_t(c)] - be), 0x1p-21 * (std::fabs(be) + std::fabs(be0)) + 1e-35)
                                << "back of vertex " << i;
                            compared += 2;
                        }
                    }
            }
        EXPECT_EQ(seen.size(), blocks.size()) << "every rendered primitive is read back";
    }
    return compared;
}

// Renders `scene` with --gltf-out and checks the asset against it: validator, JSON tree, frames.
struct AssetCase {
    fs::path scene;
    std::string options;  // besides --gltf-out and --out
    int firstFrame = 0, lastFrame = 0;
    double fps = 24;
    std::string lightingAnimation;  // the name of the animation driving the lighting ("" also: none, a still)
    int colourSet = -1;
    bool refined = false;  // --subdivide: the asset's meshes are the refined ones
};

void expectAssetIsTheInputWithTheBake(const AssetCase& c, const fs::path& out) {
    const CommandResult render = runQsgi("render " + c.scene.string() + " " + c.options + " --gltf-out --no-exr --quiet --out " + out.string());
    ASSERT_EQ(render.exitCode, 0) << render.output;
    ASSERT_TRUE(fs::exists(out / "asset.glb"));
    EXPECT_FALSE(fs::exists(out / frameName(c.firstFrame, "glb")));  // one file, not one a frame

    json input, asset;
    ASSERT_NO_THROW(input = runChecker(c.scene, "--json"));
    ASSERT_NO_THROW(asset = runChecker(out / "asset.glb", "--json"));
    const std::set<std::string> before = errorCodes(input), after = errorCodes(asset);
    for (const std::string& code : after) EXPECT_TRUE(before.count(code)) << "new validator error " << code << ": " << asset["validator"].dump(1).substr(0, 3000);

    const json in = documentJson(c.scene), baked = documentJson(out / "asset.glb");
    EXPECT_EQ(withoutTheBake(baked, in, c.colourSet, c.refined), in);

    // Where the PLY's vertices are in the asset: as the input placed them, or as the asset itself
    // (the refined meshes) does.
    EXPECT_GT(expectFramesReadBack(c.refined ? out / "asset.glb" : c.scene, out, c.firstFrame, c.lastFrame, c.fps,
                                   c.lightingAnimation, c.colourSet), 0u);
}

}  // namespace

// data/walker: skinned, its glTF animation played. The lighting's targets go into that animation,
// so a viewer playing "Walk" shows the motion and the lighting together.
TEST(GltfOut, TheWalkersAssetIsItsGltfWithEveryFrameBakedIntoItsAnimation) {
    const fs::path out = testScratchDir("gltf-out-walker");
    AssetCase c;
    c.scene = sourceDir() / "data/walker/walker.gltf";
    c.options = "--animation gltf --frames 0:2 --photons 20000 --gltf-colour 0 --threads 2" + std::string(kCheapSecondPass);
    c.lastFrame = 2;
    c.lightingAnimation = "Walk";
    c.colourSet = 0;
    expectAssetIsTheInputWithTheBake(c, out / "a");

    // Same inputs and seed, other thread count: the same bytes.
    const CommandResult one = runQsgi("render " + c.scene.string() + " " + c.options + " --threads 1 --gltf-out --no-exr --quiet --out " +
                                      (out / "b").string());
    ASSERT_EQ(one.exitCode, 0) << one.output;
    EXPECT_EQ(readFileBytes(out / "a" / "asset.glb"), readFileBytes(out / "b" / "asset.glb"));
}

// --subdivide: the asset holds the refined meshes the PLYs hold — every attribute refined alike
// (the walker's skin included), the file's own vertices first and unchanged — and qsgi reading the
// asset back finds the refined scene.
TEST(GltfOut, WithSubdivideTheAssetHoldsTheRefinedMeshes) {
    const fs::path out = testScratchDir("gltf-out-subdivide");
    AssetCase c;
    c.scene = sourceDir() / "data/walker/walker.gltf";
    c.options = "--animation gltf --frames 0:1 --photons 20000 --subdivide 0.25" + std::string(kCheapSecondPass);
    c.lastFrame = 1;
    c.lightingAnimation = "Walk";
    c.refined = true;
    expectAssetIsTheInputWithTheBake(c, out);

    Warnings w;
    const Scene input = loadGltfScene(c.scene.string(), w);
    const Scene asset = loadGltfScene((out / "asset.glb").string(), w);
    const VertexRadiosityPly ply = readVertexRadiosityPly((out / "frame_0000.ply").string());
    EXPECT_EQ(asset.vertexCount(), ply.positions.size());
    EXPECT_EQ(asset.triangleCount(), ply.triangles.size());
    EXPECT_GT(asset.vertexCount(), input.vertexCount());
    ASSERT_EQ(asset.instances.size(), input.instances.size());
    for (size_t i = 0; i < input.instances.size(); ++i) {
        const MeshInstance &a = asset.instances[i], &b = input.instances[i];
        ASSERT_GE(a.vertexCount, b.vertexCount);
        for (uint32_t v = 0; v < b.vertexCount; ++v) EXPECT_EQ(a.objectPositions[v], b.objectPositions[v]) << "instance " << i << ", vertex " << v;
        EXPECT_EQ(a.skin, b.skin);
    }
}

// data/cornell moved by a transform file: the motion is written as the asset's node animation
// "qsgi", which qsgi's own glTF reader plays back as the transform file's poses.
TEST(GltfOut, ATransformFilesMotionBecomesTheAssetsNodeAnimation) {
    const fs::path out = testScratchDir("gltf-out-cornell");
    AssetCase c;
    c.scene = sourceDir() / "data/cornell/cornell.gltf";
    c.options = "--animation " + (sourceDir() / "data/cornell/animation.json").string() + " --frames 0:3 --photons 20000" +
                std::string(kCheapSecondPass);
    c.lastFrame = 3;
    c.lightingAnimation = "qsgi";
    expectAssetIsTheInputWithTheBake(c, out);

    Warnings w;
    const Scene original = loadGltfScene(c.scene.string(), w);
    const Animation file = Animation::fromTransformFile((sourceDir() / "data/cornell/animation.json").string(), original);
    const Scene baked = loadGltfScene((out / "asset.glb").string(), w);
    ASSERT_EQ(baked.animations.size(), 1u);
    const Animation played = Animation::fromGltf(baked, 0, 24, "asset.glb");
    ASSERT_FALSE(file.movedNodes().empty());
    for (int frame = 0; frame <= 3; ++frame)
        for (const int node : file.movedNodes()) {
            const Transform a = file.localsAt(frame)[size_t(node)], b = played.localsAt(frame)[size_t(node)];
            for (int i = 0; i < 16; ++i) EXPECT_NEAR(a.m[size_t(i)], b.m[size_t(i)], 1e-6) << "frame " << frame << ", node " << node;
        }

    // One frame of it: no motion to animate, but the asset's nodes stand where the transform file
    // put them for the frame baked.
    const CommandResult single = runQsgi("render " + c.scene.string() + " --animation " + (sourceDir() / "data/cornell/animation.json").string() +
                                         " --frames 2:2 --photons 2000 --gltf-out --no-exr --quiet --out " + (out / "single").string());
    ASSERT_EQ(single.exitCode, 0) << single.output;
    const Scene still = loadGltfScene((out / "single" / "asset.glb").string(), w);
    EXPECT_TRUE(still.animations.empty());
    for (const int node : file.movedNodes()) {
        const Transform a = file.localsAt(2)[size_t(node)], b = still.nodes[size_t(node)].local;
        for (int i = 0; i < 16; ++i) EXPECT_NEAR(a.m[size_t(i)], b.m[size_t(i)], 1e-9) << "node " << node;
    }
}

// The asset is made from the frames on disk, whichever run wrote them: frames 0–1 written by a run
// of --frames-only (a Slurm chunk's way: no asset of its own, whatever --gltf-out says), then the
// range finished with --resume, gives the bytes of one straight run — every frame file and the
// asset alike.
TEST(GltfOut, AnAssetOfFramesEarlierRunsWroteIsTheStraightRunsOwn) {
    const fs::path out = testScratchDir("gltf-out-resumed");
    const std::string render = "render " + (sourceDir() / "data/cornell/cornell.gltf").string() + " --animation " +
                               (sourceDir() / "data/cornell/animation.json").string() + " --photons 5000 --gltf-out --gltf-colour 0 --no-exr --quiet" +
                               std::string(kCheapSecondPass);
    const CommandResult straight = runQsgi(render + " --frames 0:2 --out " + (out / "straight").string());
    ASSERT_EQ(straight.exitCode, 0) << straight.output;
    const CommandResult chunk = runQsgi(render + " --frames 0:1 --frames-only --out " + (out / "parts").string());
    ASSERT_EQ(chunk.exitCode, 0) << chunk.output;
    EXPECT_TRUE(fs::exists(out / "parts" / frameName(1, "ply")));
    EXPECT_FALSE(fs::exists(out / "parts" / "asset.glb")) << "--frames-only wrote an asset";
    const CommandResult finish = runQsgi(render + " --frames 0:2 --resume --out " + (out / "parts").string());
    ASSERT_EQ(finish.exitCode, 0) << finish.output;
    for (int frame = 0; frame <= 2; ++frame)
        EXPECT_EQ(readFileBytes(out / "parts" / frameName(frame, "ply")), readFileBytes(out / "straight" / frameName(frame, "ply")))
            << "frame " << frame;
    ASSERT_TRUE(fs::exists(out / "straight" / "asset.glb"));
    EXPECT_EQ(readFileBytes(out / "parts" / "asset.glb"), readFileBytes(out / "straight" / "asset.glb"));
}

// One mesh shown by four nodes: two lit differently, two under the floor in the dark (equal bakes,
// all zero). The mesh is copied only where bakes differ: the first node keeps it, the second gets a
// copy, the two dark ones share another.
TEST(GltfOut, ASharedMeshIsCopiedOnlyWhereItsBakesDiffer) {
    const fs::path dir = testScratchDir("gltf-out-shared");
    // Floor: 4 × 4 at y = 0; tile: 0.2 × 0.2 facing up. Both CCW seen from above.
    const float floor[] = {-2, 0, -2, -2, 0, 2, 2, 0, 2, 2, 0, -2};
    const float tile[] = {-0.1f, 0, -0.1f, -0.1f, 0, 0.1f, 0.1f, 0, 0.1f, 0.1f, 0, -0.1f};
    const uint32_t quad[] = {0, 1, 2, 0, 2, 3};
    {
        std::ofstream bin(dir / "shared.bin", std::ios::binary);
        bin.write(reinterpret_cast<const char*>(floor), sizeof floor);
        bin.write(reinterpret_cast<const char*>(tile), sizeof tile);
        bin.write(reinterpret_cast<const char*>(quad), sizeof quad);
    }
    const json gltf = {
        {"asset", {{"version", "2.0"}}},
        {"extensionsUsed", {"KHR_lights_punctual"}},
        {"extensions", {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 50}}}}}}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0, 1, 2, 3, 4, 5}}}}},
        {"nodes",
         {{{"name", "Floor"}, {"mesh", 0}},
          {{"name", "Lit"}, {"mesh", 1}, {"translation", {0, 0.3, 0}}},
          {{"name", "LitAside"}, {"mesh", 1}, {"translation", {1, 0.3, 0.5}}},
          {{"name", "Dark"}, {"mesh", 1}, {"translation", {0, -0.5, 0}}},
          {{"name", "DarkAside"}, {"mesh", 1}, {"translation", {1, -0.5, 0}}},
          {{"name", "Lamp"}, {"translation", {0, 1, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}}},
        {"meshes",
         {{{"name", "Floor"}, {"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 2}}}}},
          {{"name", "Tile"}, {"primitives", {{{"attributes", {{"POSITION", 1}}}, {"indices", 2}}}}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-2, 0, -2}}, {"max", {2, 0, 2}}},
          {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {-0.1, 0, -0.1}}, {"max", {0.1, 0, 0.1}}},
          {{"bufferView", 2}, {"componentType", 5125}, {"count", 6}, {"type", "SCALAR"}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
          {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 48}},
          {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 24}}}},
        {"buffers", {{{"uri", "shared.bin"}, {"byteLength", 120}}}}};
    std::ofstream(dir / "shared.gltf") << gltf.dump(1);

    AssetCase c;
    c.scene = dir / "shared.gltf";
    c.options = "--photons 20000 --threads 2" + std::string(kCheapSecondPass);
    expectAssetIsTheInputWithTheBake(c, dir / "out");
    const json asset = documentJson(dir / "out" / "asset.glb");
    ASSERT_EQ(asset["meshes"].size(), 4u) << "two copies of the tile";
    EXPECT_EQ(asset["nodes"][1]["mesh"], 1);
    EXPECT_EQ(asset["nodes"][2]["mesh"], 2);
    EXPECT_EQ(asset["nodes"][3]["mesh"], 3);
    EXPECT_EQ(asset["nodes"][4]["mesh"], 3);
}

// The Khronos samples (../shared): a textured, skinned, animated figure under a sky, a textured
// mesh whose morph targets an animation already drives (the lighting's targets follow its own, in
// its weights channel), and a .gltf whose textures are files beside it (embedded in the asset).
TEST(GltfOut, KhronosSamplesComeBackWholeWithTheBake) {
    const fs::path models = sharedDir() / "data/gltf-samples/models";
    if (!fs::exists(models)) GTEST_SKIP() << "../shared/data/gltf-samples is absent: the samples' assets are not checked";
    const fs::path out = testScratchDir("gltf-out-samples");
    {
        SCOPED_TRACE("CesiumMan");
        AssetCase c;
        c.scene = models / "CesiumMan/glTF-Binary/CesiumMan.glb";
        c.options = "--sky 1,1,1 --animation gltf --frames 0:2 --photons 20000 --gltf-colour 0" + std::string(kCheapSecondPass);
        c.lastFrame = 2;
        c.lightingAnimation = "";
        c.colourSet = 0;
        expectAssetIsTheInputWithTheBake(c, out / "cesium");
    }
    {
        SCOPED_TRACE("MorphStressTest");
        AssetCase c;
        c.scene = models / "MorphStressTest/glTF-Binary/MorphStressTest.glb";
        c.options = "--sky 1,1,1 --animation gltf:1 --frames 0:2 --photons 20000" + std::string(kCheapSecondPass);
        c.lastFrame = 2;
        c.lightingAnimation = "TheWave";
        expectAssetIsTheInputWithTheBake(c, out / "morph");
    }
    {
        SCOPED_TRACE("FlightHelmet");
        AssetCase c;
        c.scene = models / "FlightHelmet/glTF/FlightHelmet.gltf";
        c.options = "--sky 1,1,1 --photons 20000" + std::string(kCheapSecondPass);
        expectAssetIsTheInputWithTheBake(c, out / "helmet");
    }
}

// Refused before anything is computed: a colour set that would overwrite one or leave a gap, and
// an asset already baked.
TEST(GltfOut, AColourSetIsNeverOverwrittenAndABakedAssetIsNotBakedAgain) {
    const fs::path out = testScratchDir("gltf-out-refusals");
    const std::string walker = (sourceDir() / "data/walker/walker.gltf").string();
    const CommandResult gap = runQsgi("render " + walker + " --gltf-out --gltf-colour 1 --photons 1000 --out " + (out / "gap").string());
    EXPECT_EQ(gap.exitCode, 2) << gap.output;
    EXPECT_NE(gap.output.find("has no COLOR_0"), std::string::npos) << gap.output;
    EXPECT_FALSE(fs::exists(out / "gap" / "frame_0000.ply"));

    const CommandResult first = runQsgi("render " + walker + " --gltf-out --gltf-colour 0 --photons 1000 --no-exr --quiet --out " + (out / "a").string());
    ASSERT_EQ(first.exitCode, 0) << first.output;
    const std::string baked = (out / "a" / "asset.glb").string();
    const CommandResult again = runQsgi("render " + baked + " --gltf-out --photons 1000 --out " + (out / "b").string());
    EXPECT_EQ(again.exitCode, 2) << again.output;
    EXPECT_NE(again.output.find("attributes._RADIANCE: is already there"), std::string::npos) << again.output;
}

// The matrix a transform file gives becomes glTF's translation, rotation and scale.
TEST(GltfOut, AMatrixDecomposesToTheTrsThatComposeIt) {
    const std::array<double, 4> q = [] {
        const double x = 0.3, y = -0.5, z = 0.7, w = 0.4, n = std::sqrt(x * x + y * y + z * z + w * w);
        return std::array<double, 4>{x / n, y / n, z / n, w / n};
    }();
    for (const Vec3d scale : {Vec3d(1, 2, 3), Vec3d(-1, 2, 0.5), Vec3d(0.001, 1000, 1)}) {
        const Transform m = Transform::fromTRS(Vec3d(1, -2, 3), q, scale);
        const NodeTrs trs = decomposeTrs(m);
        const Transform back = trs.matrix();
        for (int i = 0; i < 16; ++i) EXPECT_NEAR(back.m[size_t(i)], m.m[size_t(i)], 1e-9 * 1000) << i;
    }
    // Flattened on one axis and rotated: the other two axes keep their directions.
    const Transform flat = Transform::fromTRS(Vec3d(0.5, 0, 0), q, Vec3d(0, 2, 3));
    const Transform back = decomposeTrs(flat).matrix();
    for (int i = 0; i < 16; ++i) EXPECT_NEAR(back.m[size_t(i)], flat.m[size_t(i)], 1e-9) << i;
}
