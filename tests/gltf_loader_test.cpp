// The loader against real files from other projects (../shared/data/gltf-samples, SOURCES.md
// gives the expected flattened triangle counts) and against the scenes shipped in data/.
#include <gtest/gtest.h>

#include <filesystem>
#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <sstream>

#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

// "scene" triangle counts, read from the tables of ../shared/data/gltf-samples/SOURCES.md, so a
// sample added there is checked without editing this file. valid/ rows: `| file | triangles | …`;
// models/ rows: `| file(s) | source | licence | exercises | scene / unique | textures |`, where
// file(s) lists several files separated by ';' and '+'. Rows without a plain count (the
// Mesh_PrimitiveMode family) are checked by primitiveModeTriangles instead.
std::vector<std::string> tableCells(const std::string& line) {
    std::vector<std::string> cells;
    size_t start = 1;
    for (size_t bar = line.find('|', start); bar != std::string::npos; start = bar + 1, bar = line.find('|', start)) {
        std::string cell = line.substr(start, bar - start);
        const size_t a = cell.find_first_not_of(' '), b = cell.find_last_not_of(' ');
        cells.push_back(a == std::string::npos ? "" : cell.substr(a, b - a + 1));
    }
    return cells;
}

std::map<std::string, size_t> expectedTriangles(const fs::path& sourcesMd) {
    std::map<std::string, size_t> expected;
    std::ifstream in(sourcesMd);
    std::string line, section;
    while (std::getline(in, line)) {
        if (line.rfind("## valid/", 0) == 0) section = "valid/";
        else if (line.rfind("## models/", 0) == 0) section = "models/";
        if (section.empty() || line.empty() || line[0] != '|') continue;
        const auto cells = tableCells(line);
        const size_t countColumn = section == "valid/" ? 1 : 4;
        if (cells.size() <= countColumn) continue;
        const std::string& count = cells[countColumn];
        if (count.empty() || !std::isdigit(static_cast<unsigned char>(count[0]))) continue;  // header, "0 or 2"
        size_t digits = 0;
        while (digits < count.size() && std::isdigit(static_cast<unsigned char>(count[digits]))) ++digits;
        if (digits < count.size() && count.substr(digits, 3) != " / ") continue;
        const size_t triangles = std::stoul(count.substr(0, digits));
        std::string files = cells[0];
        std::replace(files.begin(), files.end(), ';', '+');
        std::stringstream list(files);
        for (std::string file; std::getline(list, file, '+');) {
            const size_t a = file.find_first_not_of(' '), b = file.find_last_not_of(' ');
            if (a == std::string::npos) continue;
            file = file.substr(a, b - a + 1);
            const fs::path path(file);
            if (path.extension() == ".gltf" || path.extension() == ".glb") expected[section + file] = triangles;
        }
    }
    return expected;
}

// Mesh_PrimitiveMode README: points and lines (00-03, 07-10) give none; strips, fans, triangles 2.
size_t primitiveModeTriangles(int model) { return (model <= 3 || (model >= 7 && model <= 10)) ? 0 : 2; }

// ../shared sits beside the repository in CI but not in a user's clone; tests that need its
// samples skip with this reason there.
constexpr const char* kNoSharedSamples = "../shared/data/gltf-samples is absent (only beside the repository in CI)";
fs::path samplesDir() { return sharedDir() / "data" / "gltf-samples"; }

// The one sample of valid/ and models/ that the glTF-Validator itself rejects (19 errors,
// ACCESSOR_WEIGHTS_NON_NORMALIZED: sums as low as 0.185). glTF says float weights SHOULD sum to
// 1, so qsgi repairs them with a warning, and refuses them under --strict.
const char* const kCesiumMan = "models/CesiumMan/glTF-Binary/CesiumMan.glb";

bool isGltf(const fs::path& p) { return p.extension() == ".gltf" || p.extension() == ".glb"; }

}  // namespace

TEST(GltfLoader, EveryValidAndModelSampleLoadsWithTheDocumentedTriangleCount) {
    const auto samples = samplesDir();
    if (!fs::exists(samples)) GTEST_SKIP() << kNoSharedSamples;
    const std::map<std::string, size_t> kExpectedTriangles = expectedTriangles(samples / "SOURCES.md");
    // The tables list 13 valid/ files (besides Mesh_PrimitiveMode) and over 30 models/ files.
    ASSERT_GE(kExpectedTriangles.size(), 40u) << "SOURCES.md's tables were not read";
    size_t checked = 0;
    for (const char* folder : {"valid", "models"}) {
        for (const auto& entry : fs::recursive_directory_iterator(samples / folder)) {
            if (!entry.is_regular_file() || !isGltf(entry.path())) continue;
            const std::string rel = fs::relative(entry.path(), samples).generic_string();
            size_t expected;
            const std::string stem = entry.path().stem().string();
            if (stem.rfind("Mesh_PrimitiveMode_", 0) == 0) {
                expected = primitiveModeTriangles(std::stoi(stem.substr(19)));
            } else {
                auto it = kExpectedTriangles.find(rel);
                ASSERT_NE(it, kExpectedTriangles.end()) << rel << " is not in SOURCES.md's table";
                expected = it->second;
            }
            Warnings warnings;
            Scene scene;
            ASSERT_NO_THROW(scene = loadGltfScene(entry.path().string(), warnings)) << rel;
            EXPECT_EQ(scene.triangleCount(), expected) << rel;
            for (const auto& p : scene.positions) ASSERT_TRUE(isFinite(p)) << rel;
            for (const auto& n : scene.normals) ASSERT_NEAR(length(n), 1.0f, 1e-3f) << rel;
            ++checked;
        }
    }
    EXPECT_GE(checked, kExpectedTriangles.size() + 16);
}

TEST(GltfLoader, EveryInvalidSampleIsRejectedWithAMessageNamingTheFile) {
    const auto samples = samplesDir() / "invalid";
    if (!fs::exists(samples)) GTEST_SKIP() << kNoSharedSamples;
    size_t checked = 0;
    for (const auto& entry : fs::recursive_directory_iterator(samples)) {
        if (!entry.is_regular_file() || !isGltf(entry.path())) continue;
        Warnings warnings;
        try {
            Scene scene = loadGltfScene(entry.path().string(), warnings);
            // SOURCES.md allows "loaded with a warning where the file is usable after all".
            EXPECT_FALSE(warnings.messages.empty()) << entry.path() << " loaded silently";
        } catch (const InputError& e) {
            EXPECT_EQ(e.file(), entry.path().string());
            EXPECT_FALSE(e.problem().empty());
        }
        ++checked;
    }
    EXPECT_GE(checked, 13u);
}

TEST(GltfLoader, SpecificDefectsGiveSpecificMessages) {
    const auto samples = samplesDir() / "invalid";
    if (!fs::exists(samples)) GTEST_SKIP() << kNoSharedSamples;
    auto problemOf = [&](const std::string& rel) -> std::string {
        Warnings w;
        try {
            loadGltfScene((samples / rel).string(), w);
        } catch (const InputError& e) {
            return e.what();
        }
        return "(loaded)";
    };
    EXPECT_NE(problemOf("RecursiveNodes/RecursiveNodes.gltf").find("cycle"), std::string::npos);
    EXPECT_NE(problemOf("IndexOutOfRange/IndexOutOfRange.gltf").find("beyond"), std::string::npos);
    EXPECT_NE(problemOf("MissingBin/BoxTextured.gltf"), "(loaded)");
    EXPECT_NE(problemOf("NoScene/NoScene.gltf"), "(loaded)");
    EXPECT_NE(problemOf("SceneWithoutNodes/SceneWithoutNodes.gltf").find("no nodes"), std::string::npos);
}

TEST(GltfLoader, SamplesCarryTheirLightsCamerasAndEmission) {
    const auto models = samplesDir() / "models";
    if (!fs::exists(models)) GTEST_SKIP() << kNoSharedSamples;
    Warnings w;
    const Scene lights = loadGltfScene((models / "PlayCanvasLights/glTF-Binary/Lights.glb").string(), w);
    int point = 0, spot = 0, directional = 0;
    for (const auto& l : lights.lights) {
        point += l.type == LightType::Point;
        spot += l.type == LightType::Spot;
        directional += l.type == LightType::Directional;
    }
    EXPECT_EQ(point, 1);
    EXPECT_EQ(spot, 2);
    EXPECT_EQ(directional, 1);
    EXPECT_TRUE(lights.camera.has_value());

    // KHR_materials_emissive_strength multiplies emissiveFactor (strengths 2, 4, 8, 16).
    const Scene emissive = loadGltfScene((models / "EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb").string(), w);
    float strongest = 0;
    for (const auto& m : emissive.materials) strongest = std::max(strongest, maxComponent(m.emission));
    EXPECT_GT(strongest, 1.0f);  // a factor ≤ 1 alone could not exceed 1
}

TEST(GltfLoader, NegativeScaleKeepsFrontFacesAlongTheNormals) {
    const auto file = samplesDir() / "models/NegativeScaleQuad/glTF-Embedded/negativeScaleQuad.gltf";
    if (!fs::exists(file)) GTEST_SKIP() << kNoSharedSamples;
    Warnings w;
    const Scene s = loadGltfScene(file.string(), w);
    ASSERT_GT(s.triangleCount(), 0u);
    for (uint32_t t = 0; t < s.triangleCount(); ++t) {
        const auto& tri = s.triangles[t];
        const Vec3f vertexSide = s.normals[tri.v[0]] + s.normals[tri.v[1]] + s.normals[tri.v[2]];
        EXPECT_GT(dot(s.geometricNormal(t), vertexSide), 0.0f) << "triangle " << t;
    }
}

TEST(GltfLoader, CornellBoxHasItsPartsAndIsCentredForPrecision) {
    Warnings w;
    const Scene s = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
    EXPECT_GE(s.vertexCount(), 20000u);
    EXPECT_TRUE(w.messages.empty()) << w.messages.front();
    bool block = false;
    for (const auto& n : s.nodes) block = block || n.name == "Block";
    EXPECT_TRUE(block);
    EXPECT_TRUE(s.camera.has_value());
    // The world box spans y in [0, 2]; positions are stored relative to its centre.
    EXPECT_NEAR(s.worldOrigin.y, 1.0, 1e-6);
    EXPECT_NEAR(s.bounds().lower.y, -1.0f, 1e-5f);
}

// The messages among `warnings` that contain `words`.
static size_t countContaining(const Warnings& warnings, const std::string& words) {
    return size_t(std::count_if(warnings.messages.begin(), warnings.messages.end(),
                                [&](const std::string& m) { return m.find(words) != std::string::npos; }));
}

// glTF 2.0 (§3.7.3.3): float joint weights SHOULD sum to 1. CesiumMan's do not (the validator
// reports 19 errors): it loads with one warning naming the accessor and the vertices repaired,
// every frame of its animation poses finite and visible; under --strict it is refused, naming
// the accessor.
TEST(GltfLoader, CesiumMansUnnormalisedWeightsAreRepairedWithOneWarningAndRefusedUnderStrict) {
    const fs::path file = samplesDir() / kCesiumMan;
    if (!fs::exists(file)) GTEST_SKIP() << kNoSharedSamples;
    Warnings warnings;
    Scene scene;
    ASSERT_NO_THROW(scene = loadGltfScene(file.string(), warnings));
    EXPECT_EQ(countContaining(warnings, "WEIGHTS"), 1u);
    EXPECT_EQ(countContaining(warnings, "weight"), 1u);
    const size_t at = size_t(std::find_if(warnings.messages.begin(), warnings.messages.end(), [](const std::string& m) {
                                 return m.find("WEIGHTS") != std::string::npos;
                             }) - warnings.messages.begin());
    ASSERT_LT(at, warnings.messages.size());
    const std::string& message = warnings.messages[at];
    EXPECT_NE(message.find("meshes[0].primitives[0].attributes.WEIGHTS_0 (accessor 5)"), std::string::npos) << message;
    EXPECT_NE(message.find(" of 3273 vertices"), std::string::npos) << message;
    EXPECT_NE(message.find("renormalised to sum 1"), std::string::npos) << message;
    // Repaired, every vertex is held by its joints in every frame: finite and not hidden.
    const Animation walk = Animation::fromGltf(scene, -1, 24, "test");
    ASSERT_GT(walk.lastFrame(), 0);
    for (int frame = 0; frame <= walk.lastFrame(); frame += 7) {
        scene.applyPose(walk.poseAt(frame));
        for (size_t v = 0; v < scene.positions.size(); ++v) {
            ASSERT_TRUE(isFinite(scene.positions[v])) << "frame " << frame << ", vertex " << v;
            ASSERT_FALSE(scene.vertexHidden[v]) << "frame " << frame << ", vertex " << v;
        }
    }
    // Rendered through the executable (three frames of its walk, lit by a config's lamp): exit 0,
    // one warning line about the weights.
    const fs::path dir = testScratchDir("cesium-man");
    const nlohmann::json config = {
        {"scene", file.string()}, {"animation", "gltf"}, {"frames", "0:2"}, {"photons", 2000},
        {"lights", {{{"type", "point"}, {"position", {0, 3, 1}}, {"intensity", {10, 10, 10}}}}}};
    std::ofstream(dir / "config.json") << config.dump();
    const CommandResult render = runQsgi("render --config " + (dir / "config.json").string() + " --no-exr --out " +
                                         (dir / "out").string());
    EXPECT_EQ(render.exitCode, 0) << render.output;
    EXPECT_TRUE(fs::exists(dir / "out" / "frame_0002.ply")) << render.output;
    size_t lines = 0;
    for (size_t p = render.output.find("WEIGHTS_0"); p != std::string::npos; p = render.output.find("WEIGHTS_0", p + 1)) ++lines;
    EXPECT_EQ(lines, 1u) << render.output;

    Warnings strictWarnings;
    try {
        loadGltfScene(file.string(), strictWarnings, GltfReadOptions{true});
        ADD_FAILURE() << "--strict loaded weights that do not sum to 1";
    } catch (const InputError& e) {
        EXPECT_EQ(e.file(), file.string());
        EXPECT_EQ(e.place(), "meshes[0].primitives[0].attributes.WEIGHTS_0") << e.what();
        EXPECT_NE(e.problem().find("accessor 5"), std::string::npos) << e.what();
        EXPECT_NE(e.problem().find("--strict refuses them"), std::string::npos) << e.what();
    }
}

namespace {

// Two joints, Root (node 0) at the origin and its child Tip (node 1) at x = 1, bound where they
// stand, and a strip of six vertices (columns x = 0, 1, 2; rows y = 0, 0.2) skinned to them by
// `weights` (four a vertex) and `joints` (unsigned bytes, four a vertex), drawn by two nodes
// through two meshes that share every accessor. A lamp above.
fs::path writeSkinnedStrip(const std::string& name, const std::vector<float>& weights, const std::vector<uint8_t>& joints) {
    testscenes::GltfWriter w;
    const int positions = w.accessor({0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 0.2f, 0, 1, 0.2f, 0, 2, 0.2f, 0}, "VEC3");
    const int indices = w.indices({0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4});
    const int weightAccessor = w.accessor(weights, "VEC4");
    while (w.bin.size() % 4) w.bin.push_back('\0');
    w.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", w.bin.size()}, {"byteLength", joints.size()}});
    w.bin.append(reinterpret_cast<const char*>(joints.data()), joints.size());
    w.doc["accessors"].push_back({{"bufferView", w.doc["bufferViews"].size() - 1}, {"componentType", 5121},
                                  {"count", joints.size() / 4}, {"type", "VEC4"}});
    const int jointAccessor = int(w.doc["accessors"].size()) - 1;
    const int inverseBind = w.accessor({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                                        1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1}, "MAT4");
    const nlohmann::json primitive = {{"attributes", {{"POSITION", positions}, {"JOINTS_0", jointAccessor},
                                                      {"WEIGHTS_0", weightAccessor}}}, {"indices", indices}};
    w.doc["meshes"] = nlohmann::json::array({{{"name", "Strip"}, {"primitives", {primitive}}},
                                            {{"name", "StripAgain"}, {"primitives", {primitive}}}});
    w.node({{"name", "Root"}, {"children", {1}}});
    w.node({{"name", "Tip"}, {"translation", {1, 0, 0}}});
    w.node({{"name", "Strip"}, {"mesh", 0}, {"skin", 0}});
    w.node({{"name", "StripAgain"}, {"mesh", 1}, {"skin", 0}});
    w.node({{"name", "Lamp"}, {"translation", {1, 3, 2}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    w.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", nlohmann::json::array({{{"type", "point"}, {"intensity", 20}}})}}}};
    w.doc["scenes"] = nlohmann::json::array({{{"nodes", {0, 2, 3, 4}}}});
    w.doc["skins"] = nlohmann::json::array({{{"joints", {0, 1}}, {"inverseBindMatrices", inverseBind}}});
    const fs::path path = fs::path(testScratchDir("skin-weights-" + name)) / "strip.gltf";
    w.write(path.string());
    return path;
}

}  // namespace

// Weights that sum to 0.5, and a vertex whose weights are all zero, load with one warning that
// counts them (the two meshes share the accessor), and pose exactly as the same strip with the
// weights normalised by hand, the all-zero vertex given weight 1 on its first joint (Tip).
TEST(GltfLoader, UnnormalisedFloatWeightsAreRenormalisedWithOneWarningAndPoseAsNormalisedOnes) {
    // Vertex 3, (0, 0.2, 0), is all zero; its first joint is Tip (1).
    const std::vector<uint8_t> joints = {0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0};
    const std::vector<float> halves = {0.5f, 0, 0, 0, 0.25f, 0.25f, 0, 0, 0.5f, 0, 0, 0,
                                       0, 0, 0, 0, 0.125f, 0.375f, 0, 0, 0.1f, 0.4f, 0, 0};
    std::vector<float> normalised = halves;
    for (float& x : normalised) x *= 2;
    normalised[12] = 1;  // vertex 3: all of it on its first joint
    const fs::path repairedFile = writeSkinnedStrip("halves", halves, joints);
    const fs::path normalisedFile = writeSkinnedStrip("normalised", normalised, joints);

    Warnings warnings, none;
    Scene repaired, reference;
    ASSERT_NO_THROW(repaired = loadGltfScene(repairedFile.string(), warnings));
    ASSERT_NO_THROW(reference = loadGltfScene(normalisedFile.string(), none));
    EXPECT_TRUE(none.messages.empty()) << none.messages.front();
    ASSERT_EQ(countContaining(warnings, "WEIGHTS_0"), 1u);
    ASSERT_EQ(warnings.messages.size(), 1u) << warnings.messages.back();
    const std::string& message = warnings.messages[0];
    EXPECT_NE(message.find("meshes[0].primitives[0].attributes.WEIGHTS_0 (accessor 2)"), std::string::npos) << message;
    EXPECT_NE(message.find("6 of 6 vertices"), std::string::npos) << message;
    EXPECT_NE(message.find("1 whose weights are all zero given weight 1 on their first joint"), std::string::npos) << message;

    // A pose that moves both joints: Root along +y, Tip turned 90° about +z.
    ASSERT_EQ(repaired.positions.size(), reference.positions.size());
    std::vector<Transform> locals = repaired.restLocals();
    locals[0] = Transform::fromTRS(Vec3d(0, 0.5, 0), {0, 0, 0, 1}, Vec3d(1.0));
    locals[1] = locals[1] * Transform::fromTRS(Vec3d(0.0), {0, 0, std::sqrt(0.5), std::sqrt(0.5)}, Vec3d(1.0));
    repaired.applyPose(Pose(locals));
    reference.applyPose(Pose(locals));
    for (size_t v = 0; v < repaired.positions.size(); ++v) {
        const Vec3d a = Vec3d(repaired.positions[v]) + repaired.worldOrigin, b = Vec3d(reference.positions[v]) + reference.worldOrigin;
        EXPECT_NEAR(a.x, b.x, 1e-6) << "vertex " << v;
        EXPECT_NEAR(a.y, b.y, 1e-6) << "vertex " << v;
        EXPECT_NEAR(a.z, b.z, 1e-6) << "vertex " << v;
        EXPECT_FALSE(repaired.vertexHidden[v]) << "vertex " << v;
    }
    // The all-zero vertex 3, (0, 0.2, 0), follows its first joint, Tip, alone (not Root, nor the
    // node): T(0,0.5,0)·T(1,0,0)·Rz(90°)·T(−1,0,0) maps (x, y, z) to (1 − y, 0.5 + x − 1, z), so it
    // is at (0.8, −0.5, 0), in both instances.
    for (const MeshInstance& instance : repaired.instances) {
        const Vec3d p = Vec3d(repaired.positions[instance.firstVertex + 3]) + repaired.worldOrigin;
        EXPECT_NEAR(p.x, 0.8, 1e-6);
        EXPECT_NEAR(p.y, -0.5, 1e-6);
        EXPECT_NEAR(p.z, 0.0, 1e-6);
    }

    // Under --strict the same weights are refused, naming the accessor.
    try {
        Warnings strictWarnings;
        loadGltfScene(repairedFile.string(), strictWarnings, GltfReadOptions{true});
        ADD_FAILURE() << "--strict loaded weights that sum to 0.5";
    } catch (const InputError& e) {
        EXPECT_EQ(e.place(), "meshes[0].primitives[0].attributes.WEIGHTS_0") << e.what();
        EXPECT_NE(e.problem().find("6 of 6 vertices have weights that do not sum to 1 (vertex 0's sum to 0.5"), std::string::npos)
            << e.what();
        EXPECT_NE(e.problem().find("accessor 2"), std::string::npos) << e.what();
    }
}

// What glTF makes a MUST stays refused with or without --strict: normalized-integer weights
// whose sum before normalization is not 255 (here 128 + 64), a negative weight, a joint named
// twice with non-zero weights.
TEST(GltfLoader, SkinWeightsBreakingAMustAreRefusedWithoutStrict) {
    const std::vector<uint8_t> joints = {0, 1, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0};
    const std::vector<float> ones = {1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0.25f, 0.75f, 0, 0, 0.5f, 0.5f, 0, 0};
    auto problemOf = [](const fs::path& file) -> std::string {
        Warnings w;
        try {
            loadGltfScene(file.string(), w);
        } catch (const InputError& e) {
            return e.what();
        }
        return "(loaded)";
    };
    EXPECT_EQ(problemOf(writeSkinnedStrip("ones", ones, joints)), "(loaded)");

    // The weights as normalized unsigned bytes: 255 a vertex, then vertex 1's 128 + 64.
    const fs::path bytesFile = writeSkinnedStrip("bytes", ones, joints);
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(bytesFile));
    const std::vector<uint8_t> bytes = {255, 0, 0, 0, 128, 64, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0, 64, 191, 0, 0, 128, 127, 0, 0};
    std::string bin(bytes.begin(), bytes.end());
    static const char* b64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string uri = "data:application/octet-stream;base64,";
    for (size_t i = 0; i < bin.size(); i += 3) {
        const uint32_t v = uint32_t(uint8_t(bin[i])) << 16 | uint32_t(uint8_t(bin[i + 1])) << 8 | uint32_t(uint8_t(bin[i + 2]));
        for (int shift : {18, 12, 6, 0}) uri += b64[(v >> shift) & 63];
    }
    doc["buffers"].push_back({{"byteLength", bytes.size()}, {"uri", uri}});
    doc["bufferViews"].push_back({{"buffer", 1}, {"byteLength", bytes.size()}});
    doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1}, {"componentType", 5121}, {"normalized", true},
                                {"count", 6}, {"type", "VEC4"}});
    for (auto& mesh : doc["meshes"]) mesh["primitives"][0]["attributes"]["WEIGHTS_0"] = doc["accessors"].size() - 1;
    const fs::path normalizedFile = bytesFile.parent_path() / "bytes-192.gltf";
    std::ofstream(normalizedFile) << doc.dump();
    const std::string normalized = problemOf(normalizedFile);
    EXPECT_NE(normalized.find("attributes.WEIGHTS_0: vertex 1's weights sum to 0.75"), std::string::npos) << normalized;
    EXPECT_NE(normalized.find("255 or 65535"), std::string::npos) << normalized;

    std::vector<float> negative = ones;
    negative[5] = -0.5f;
    negative[4] = 1.5f;
    EXPECT_NE(problemOf(writeSkinnedStrip("negative", negative, joints)).find("negative weight"), std::string::npos);
    std::vector<uint8_t> twice = joints;
    twice[5] = 0;  // vertex 1 names joint 0 twice, both weighted 0.5
    EXPECT_NE(problemOf(writeSkinnedStrip("twice", ones, twice)).find("names joint 0 twice"), std::string::npos);
}
