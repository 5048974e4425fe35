// asset.usda (--usd-out, lib/output/usd_asset.h). What OpenUSD itself reads back from it — every
// frame's samples against its PLY, names, time codes, the preview material's wiring, OpenUSD's own
// validation — is checked by UsdOut.EveryFrameReadsBackInOpenUsd (scripts/usd-check/check_usd.py);
// these tests check what needs no OpenUSD.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <set>

#include "output/usd_asset.h"
#include "output/usd_identifiers.h"
#include "scene/gltf_loader.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

TEST(UsdIdentifiers, GltfNamesBecomeIdentifiersUniqueAmongSiblings) {
    EXPECT_EQ(usdIdentifier("Floor", "Mesh"), "Floor");
    EXPECT_EQ(usdIdentifier("", "Mesh"), "Mesh");
    EXPECT_EQ(usdIdentifier("2CylinderEngine", "Mesh"), "_2CylinderEngine");
    EXPECT_EQ(usdIdentifier("left wall.001", "Mesh"), "left_wall_001");
    EXPECT_EQ(usdIdentifier("Stuhl/Bein-1", "Mesh"), "Stuhl_Bein_1");
    EXPECT_EQ(usdIdentifier("\xc3\x9c" "ber", "Mesh"), "__ber");  // Ü: two bytes, two underscores

    UniqueNames names;
    EXPECT_EQ(names.claim("Mesh"), "Mesh");
    EXPECT_EQ(names.claim("Mesh"), "Mesh_1");
    EXPECT_EQ(names.claim("Mesh"), "Mesh_2");
    EXPECT_EQ(names.claim("Mesh_1"), "Mesh_1_1");  // a file's own "Mesh_1", after a clash took the name
    EXPECT_EQ(names.claim("Other"), "Other");
    // Every name claimed is a valid identifier, and none repeats.
    UniqueNames many;
    std::set<std::string> seen;
    for (const char* raw : {"a b", "a_b", "a-b", "a.b", "", "", "9", "_9", "9"}) {
        const std::string name = many.claim(usdIdentifier(raw, "Node"));
        ASSERT_FALSE(name.empty());
        EXPECT_TRUE(name[0] == '_' || std::isalpha(static_cast<unsigned char>(name[0]))) << name;
        for (const char c : name) EXPECT_TRUE(c == '_' || std::isalnum(static_cast<unsigned char>(c))) << name;
        EXPECT_TRUE(seen.insert(name).second) << name << " repeats";
    }
}

namespace {
// Frames of data/walker's scene made up for the writer: every vertex's values drawn at random per
// frame, the figure (skinned) moved along x frame by frame, everything else where the scene has it.
VertexRadiosityPly madeUpFrame(const Scene& scene, int frame) {
    std::mt19937 random(uint32_t(1000 + frame));
    std::uniform_real_distribution<float> value(0.0f, 3.0f);
    VertexRadiosityPly ply;
    for (const MeshInstance& inst : scene.instances)
        for (uint32_t i = 0; i < inst.vertexCount; ++i) {
            const uint32_t v = inst.firstVertex + i;
            const Vec3f shift(inst.deforms() ? 0.1f * float(frame) : 0.0f, 0, 0);
            ply.positions.push_back(Vec3f(Vec3d(scene.positions[v]) + scene.worldOrigin) + shift);
            ply.normals.push_back(scene.normals[v]);
            ply.radiosity.push_back(Vec3f(value(random), value(random), value(random)));
            ply.irradiance.push_back(Vec3f(value(random), value(random), value(random)));
        }
    return ply;
}
}  // namespace

// The meshes are written in groups whose frames fit the memory budget, each group reading every
// frame once: a budget that holds one mesh at a time gives the bytes of one that holds them all.
TEST(UsdOut, AGroupOfMeshesAtATimeWritesTheBytesOfAllAtOnce) {
    Warnings warnings;
    const Scene scene = loadGltfScene((sourceDir() / "data/walker/walker.gltf").string(), warnings);
    ASSERT_GT(scene.instances.size(), 3u);
    UsdAssetSettings settings;
    settings.first = 3;
    settings.last = 6;
    settings.fps = 30;
    settings.source = "walker.gltf";
    settings.nodeWorldAt = [&](int) { return scene.worldTransforms(scene.restLocals()); };
    auto write = [&](uint64_t budget, UsdAssetSummary& summary, int& reads) {
        settings.memoryBudget = budget;
        std::string text;
        reads = 0;
        writeUsdAsset(
            scene, settings,
            [&](int frame) {
                ++reads;
                return madeUpFrame(scene, frame);
            },
            [&](std::string_view piece) { text += piece; }, &summary);
        return text;
    };
    UsdAssetSummary whole, apart;
    int wholeReads = 0, apartReads = 0;
    const std::string all = write(UINT64_MAX, whole, wholeReads);
    const std::string oneByOne = write(1, apart, apartReads);
    EXPECT_EQ(whole.framePasses, 1u);
    EXPECT_EQ(apart.framePasses, scene.instances.size());
    EXPECT_EQ(wholeReads, 4);
    EXPECT_EQ(apartReads, 4 * int(scene.instances.size()));
    EXPECT_EQ(all.size(), whole.bytes);
    EXPECT_EQ(whole.points, scene.vertexCount());
    EXPECT_EQ(whole.frames, 4u);
    EXPECT_TRUE(all == oneByOne) << "the layer depends on how the meshes were grouped";
    // The figure's points moved: sampled at every frame. The layer's frame range and rate.
    EXPECT_NE(all.find("point3f[] points.timeSamples"), std::string::npos);
    EXPECT_NE(all.find("startTimeCode = 3\n"), std::string::npos);
    EXPECT_NE(all.find("endTimeCode = 6\n"), std::string::npos);
    EXPECT_NE(all.find("timeCodesPerSecond = 30\n"), std::string::npos);
}

// Like asset.glb, asset.usda is made from the frames on disk, whichever run wrote them: frames 0–1
// by a run of --frames-only (no asset of its own), the range finished with --resume, gives the
// bytes of one straight run. A later run that computes frames removes the asset it would outdate.
TEST(UsdOut, AnAssetOfFramesEarlierRunsWroteIsTheStraightRunsOwn) {
    const fs::path out = testScratchDir("usd-out-resumed");
    const std::string render = "render " + (sourceDir() / "data/walker/walker.gltf").string() +
                               " --animation gltf --photons 5000 --usd-out --no-exr --quiet" + std::string(kCheapSecondPass);
    const CommandResult straight = runQsgi(render + " --frames 0:2 --out " + (out / "straight").string());
    ASSERT_EQ(straight.exitCode, 0) << straight.output;
    const CommandResult chunk = runQsgi(render + " --frames 0:1 --frames-only --out " + (out / "parts").string());
    ASSERT_EQ(chunk.exitCode, 0) << chunk.output;
    EXPECT_FALSE(fs::exists(out / "parts" / "asset.usda")) << "--frames-only wrote an asset";
    const CommandResult finish = runQsgi(render + " --frames 0:2 --resume --out " + (out / "parts").string());
    ASSERT_EQ(finish.exitCode, 0) << finish.output;
    ASSERT_TRUE(fs::exists(out / "straight" / "asset.usda"));
    EXPECT_TRUE(readFileBytes(out / "parts" / "asset.usda") == readFileBytes(out / "straight" / "asset.usda"));

    // Frame 3 computed without --usd-out: the asset of frames 0–2 no longer stands for the folder.
    const std::string plain = "render " + (sourceDir() / "data/walker/walker.gltf").string() +
                              " --animation gltf --photons 5000 --no-exr --quiet" + std::string(kCheapSecondPass);
    const CommandResult more = runQsgi(plain + " --frames 0:3 --resume --out " + (out / "parts").string());
    ASSERT_EQ(more.exitCode, 0) << more.output;
    EXPECT_FALSE(fs::exists(out / "parts" / "asset.usda"));
}

// What tools choke on, or show where qsgi shows nothing, is left out of the layer: a triangle naming
// a vertex twice (no area; Blender's importer drops such a mesh's primvars, or crashes), and a node
// hidden by a scale of zero on one axis, which qsgi collapses to the node's origin (a flat sheet
// under the singular transform would be in view, black).
TEST(UsdOut, DegenerateTrianglesAndHiddenNodesShowAsQsgiComputedThem) {
    Scene scene;
    scene.materials.push_back(Material{"Grey", Vec3f(0.5f), Vec3f(0.0f)});
    const int node = scene.addNode("Panel", Transform::fromTRS(Vec3d(1, 2, 3), {0, 0, 0, 1}, Vec3d(1.0)));
    scene.addInstance(node, {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 0, 1), Vec3f(1, 0, 1)}, {},
                      {0, 2, 1, 1, 2, 3, 1, 1, 3}, 0);  // the last triangle names vertex 1 twice
    scene.finalize();
    UsdAssetSettings settings;
    settings.first = 0;
    settings.last = 1;
    settings.fps = 24;
    settings.nodeWorldAt = [&](int frame) {
        // Frame 1: flattened to nothing along y and z, as a glTF animation hides a node.
        return std::vector<Transform>{Transform::fromTRS(Vec3d(1, 2, 3), {0, 0, 0, 1}, frame == 0 ? Vec3d(1.0) : Vec3d(1, 0, 0))};
    };
    std::string text;
    writeUsdAsset(
        scene, settings,
        [&](int) {
            VertexRadiosityPly ply;
            for (size_t v = 0; v < scene.vertexCount(); ++v) {
                ply.positions.push_back(Vec3f(Vec3d(scene.positions[v]) + scene.worldOrigin));
                ply.normals.push_back(scene.normals[v]);
                ply.radiosity.push_back(Vec3f(1.0f));
                ply.irradiance.push_back(Vec3f(2.0f));
            }
            return ply;
        },
        [&](std::string_view piece) { text += piece; });
    EXPECT_NE(text.find("int[] faceVertexCounts = [3,3]\n"), std::string::npos) << text;
    EXPECT_NE(text.find("int[] faceVertexIndices = [0,2,1,1,2,3]\n"), std::string::npos) << text;
    // Frame 0 placed as the node is; frame 1 every point at the node's origin (1, 2, 3).
    EXPECT_NE(text.find("0: ((1,0,0,0), (0,1,0,0), (0,0,1,0), (1,2,3,1)),"), std::string::npos) << text;
    EXPECT_NE(text.find("1: ((0,0,0,0), (0,0,0,0), (0,0,0,0), (1,2,3,1)),"), std::string::npos) << text;
}
