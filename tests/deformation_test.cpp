// Deforming meshes (issue 11): a two-bone skinned strip and a one-target morph give the vertex
// positions worked out by hand, the third-party skinned and morphing samples animate, and the
// incremental update equals a full recomputation for a deforming mesh over many frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "util/error.h"

using namespace qsgi;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// A strip in the xy-plane, columns at x = 0, 1, 2 and rows at y = 0 and 0.2, facing +z, above a
// floor and under a lamp. Bones: "Root" (joint 0) at the origin and its child "Tip" (joint 1) at
// x = 1, bound where they stand (inverse bind matrices: identity and a translation by −1 in x).
// Column 0 follows Root, column 2 Tip, column 1 half of each. The strip's own node sits at
// x = 5, which a skinned mesh ignores. The animation turns Tip by 90° about +z over 1 s (LINEAR).
// A second mesh, "Blob" (a quad at y = 1), has one morph target lifting vertex 2 by (0, 0, 1),
// its weight 0.25 at rest (mesh.weights) and animated from 0 to 1 over 1 s.
// unweightedJoint: the joint vertex 0 names in its third influence, whose weight is 0.
fs::path writeDeformingScene(const std::string& name, bool withFloorAndLamp, uint8_t unweightedJoint = 0,
                             float inverseBindCorner = 1) {
    testscenes::GltfWriter w;
    const int stripPositions = w.accessor({0, 0, 0, 1, 0, 0, 2, 0, 0, 0, 0.2f, 0, 1, 0.2f, 0, 2, 0.2f, 0}, "VEC3");
    const int stripNormals = w.accessor({0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}, "VEC3");
    const int stripIndices = w.indices({0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4});
    // JOINTS_0 as unsigned bytes (VEC4): written through a float accessor's bytes would be wrong,
    // so they go in by hand below.
    const int weights = w.accessor({1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 0.5f, 0.5f, 0, 0, 0, 1, 0, 0}, "VEC4");
    std::vector<uint8_t> jointBytes = {0, 1, unweightedJoint, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0};
    while (w.bin.size() % 4) w.bin.push_back('\0');
    w.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", w.bin.size()}, {"byteLength", jointBytes.size()}});
    w.bin.append(reinterpret_cast<const char*>(jointBytes.data()), jointBytes.size());
    w.doc["accessors"].push_back({{"bufferView", w.doc["bufferViews"].size() - 1}, {"componentType", 5121},
                                  {"count", 6}, {"type", "VEC4"}});
    const int joints = int(w.doc["accessors"].size()) - 1;
    const int inverseBind = w.accessor({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1,
                                        1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, inverseBindCorner}, "MAT4");
    const int quad = w.accessor({-0.5f, 1, 0, 0.5f, 1, 0, 0.5f, 1.5f, 0, -0.5f, 1.5f, 0}, "VEC3");
    const int quadIndices = w.indices({0, 1, 2, 0, 2, 3});
    const int lift = w.accessor({0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0}, "VEC3");
    const int floorPositions = w.accessor({-3, -1, 3, 3, -1, 3, 3, -1, -3, -3, -1, -3}, "VEC3");

    json meshes = json::array();
    meshes.push_back({{"name", "Strip"}, {"primitives", json::array({{{"attributes", {{"POSITION", stripPositions},
        {"NORMAL", stripNormals}, {"JOINTS_0", joints}, {"WEIGHTS_0", weights}}}, {"indices", stripIndices}}})}});
    meshes.push_back({{"name", "Blob"}, {"weights", {0.25}}, {"primitives", json::array({{{"attributes", {{"POSITION", quad}}},
        {"indices", quadIndices}, {"targets", json::array({{{"POSITION", lift}}})}}})}});
    meshes.push_back({{"name", "Floor"}, {"primitives", json::array({{{"attributes", {{"POSITION", floorPositions}}},
        {"indices", quadIndices}}})}});
    w.doc["meshes"] = meshes;
    const int root = w.node({{"name", "Root"}, {"children", {1}}});
    w.node({{"name", "Tip"}, {"translation", {1, 0, 0}}});
    const int strip = w.node({{"name", "Strip"}, {"mesh", 0}, {"skin", 0}, {"translation", {5, 0, 0}}});
    const int blob = w.node({{"name", "Blob"}, {"mesh", 1}});
    std::vector<int> roots = {root, strip, blob};
    if (withFloorAndLamp) {
        roots.push_back(w.node({{"name", "Floor"}, {"mesh", 2}}));
        roots.push_back(w.node({{"name", "Lamp"}, {"translation", {1, 3, 2}},
                                {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}));
        w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
        w.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({{{"type", "point"}, {"intensity", 20}}})}}}};
    }
    w.doc["scenes"] = json::array({{{"nodes", roots}}});
    w.doc["skins"] = json::array({{{"joints", {0, 1}}, {"inverseBindMatrices", inverseBind}}});
    const double s = std::sqrt(0.5);
    const int times = w.accessor({0, 1}, "SCALAR");
    const int turn = w.accessor({0, 0, 0, 1, 0, 0, float(s), float(s)}, "VEC4");
    const int weightKeys = w.accessor({0, 1}, "SCALAR");
    w.doc["animations"] = json::array({{{"name", "Bend"},
        {"samplers", json::array({{{"input", times}, {"output", turn}}, {{"input", times}, {"output", weightKeys}}})},
        {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 1}, {"path", "rotation"}}}},
                                  {{"sampler", 1}, {"target", {{"node", blob}, {"path", "weights"}}}}})}}});
    const fs::path path = fs::path(testScratchDir("deformation-" + name)) / "scene.gltf";
    w.write(path.string());
    return path;
}

Vec3d worldPosition(const Scene& scene, uint32_t vertex) { return Vec3d(scene.positions[vertex]) + scene.worldOrigin; }

void expectNear(const Vec3d& a, const Vec3d& b, double tolerance, const std::string& what) {
    EXPECT_NEAR(a.x, b.x, tolerance) << what;
    EXPECT_NEAR(a.y, b.y, tolerance) << what;
    EXPECT_NEAR(a.z, b.z, tolerance) << what;
}

}  // namespace

TEST(Deformation, TwoBoneStripAndOneTargetMorphGiveHandWorkedPositions) {
    Warnings warnings;
    Scene scene = loadGltfScene(writeDeformingScene("positions", false).string(), warnings);
    ASSERT_EQ(scene.instances.size(), 2u);
    const MeshInstance& strip = scene.instances[0];
    const MeshInstance& blob = scene.instances[1];
    // At rest the bones stand where they were bound: the strip is where its positions say (the
    // node's x = 5 ignored); the blob carries its rest weight 0.25.
    for (uint32_t v = 0; v < 6; ++v)
        expectNear(worldPosition(scene, strip.firstVertex + v), Vec3d(strip.objectPositions[v]), 1e-6, "rest " + std::to_string(v));
    expectNear(worldPosition(scene, blob.firstVertex + 2), Vec3d(0.5, 1.5, 0.25), 1e-6, "blob at rest");

    const Animation bend = Animation::fromGltf(scene, -1, 24, "test");
    EXPECT_EQ(bend.lastFrame(), 24);
    EXPECT_EQ(bend.morphedNodes(), std::vector<int>{3});
    scene.applyPose(bend.poseAt(24));  // t = 1: Tip turned 90° about +z, the blob's weight 1
    // Tip's matrix J·IBM = T(1,0,0)·Rz(90°)·T(−1,0,0) maps (x, y, z) to (1 − y, x − 1, z).
    // Column 2 follows it: (2, 0) → (1, 1); (2, 0.2) → (0.8, 1).
    expectNear(worldPosition(scene, strip.firstVertex + 2), Vec3d(1, 1, 0), 1e-6, "tip, row 0");
    expectNear(worldPosition(scene, strip.firstVertex + 5), Vec3d(0.8, 1, 0), 1e-6, "tip, row 1");
    // Column 1 blends half of each: ((1, 0.2) + (0.8, 0)) / 2 = (0.9, 0.1); (1, 0) stays.
    expectNear(worldPosition(scene, strip.firstVertex + 4), Vec3d(0.9, 0.1, 0), 1e-6, "middle, row 1");
    expectNear(worldPosition(scene, strip.firstVertex + 1), Vec3d(1, 0, 0), 1e-6, "middle, row 0");
    // Column 0 follows Root, which does not move.
    expectNear(worldPosition(scene, strip.firstVertex + 3), Vec3d(0, 0.2, 0), 1e-6, "root");
    // A rotation about z keeps the +z normals (the inverse-transpose of a rotation is itself).
    EXPECT_NEAR(scene.normals[strip.firstVertex + 5].z, 1.0f, 1e-6f);
    // The morph: p₂ + 1·(0, 0, 1); the other vertices have no delta.
    expectNear(worldPosition(scene, blob.firstVertex + 2), Vec3d(0.5, 1.5, 1), 1e-6, "blob, weight 1");
    expectNear(worldPosition(scene, blob.firstVertex + 1), Vec3d(0.5, 1, 0), 1e-6, "blob vertex 1");
    // Halfway (frame 12): Tip at 45° (spherical), weight 0.5.
    scene.applyPose(bend.poseAt(12));
    const double c = std::sqrt(0.5);
    expectNear(worldPosition(scene, strip.firstVertex + 2), Vec3d(1 + c, c, 0), 1e-6, "tip at 45°");
    expectNear(worldPosition(scene, blob.firstVertex + 2), Vec3d(0.5, 1.5, 0.5), 1e-6, "blob, weight 0.5");
}

TEST(Deformation, SkinnedAndMorphingSamplesAnimateWithFiniteGeometry) {
    const fs::path models = sharedDir() / "data/gltf-samples/models";
    if (!fs::exists(models)) GTEST_SKIP() << "../shared is absent: " << models;
    // Fox, RiggedFigure and CesiumMan are skinned; CesiumMan's weights do not sum to 1 and load
    // renormalised, with a warning (GltfLoader.CesiumMansUnnormalisedWeights…).
    for (const char* file : {"Fox/glTF-Binary/Fox.glb", "RiggedFigure/glTF-Binary/RiggedFigure.glb",
                             "CesiumMan/glTF-Binary/CesiumMan.glb",
                             "MorphStressTest/glTF-Binary/MorphStressTest.glb"}) {
        SCOPED_TRACE(file);
        Warnings warnings;
        Scene scene = loadGltfScene((models / file).string(), warnings);
        const Animation a = Animation::fromGltf(scene, 0, 24, file);
        EXPECT_GT(a.lastFrame(), 10);
        EXPECT_FALSE(a.movedNodes().empty() && a.morphedNodes().empty());
        scene.setRestPose(a.poseAt(0));
        scene.markDynamic(a.movedNodes(), a.morphedNodes());
        EXPECT_TRUE(scene.hasDynamicGeometry());
        const std::vector<Vec3f> first = scene.positions;
        std::vector<uint8_t> moved(scene.vertexCount(), 0);  // walk cycles end where they began
        for (int frame = 1; frame <= a.lastFrame(); ++frame) {
            scene.applyPose(a.poseAt(frame));
            for (size_t v = 0; v < scene.vertexCount(); ++v) {
                ASSERT_TRUE(isFinite(scene.positions[v]) && isFinite(scene.normals[v])) << "frame " << frame << " vertex " << v;
                ASSERT_NEAR(length(scene.normals[v]), 1.0f, 1e-4f) << "frame " << frame << " vertex " << v;
                moved[v] |= !(scene.positions[v] == first[v]);
            }
        }
        EXPECT_GT(std::count(moved.begin(), moved.end(), 1), 0);
    }
}

TEST(Deformation, IncrementalEqualsFullRecomputationForADeformingMesh) {
    // 49 frames of the bending strip and the swelling blob over a floor: every frame's bytes
    // equal a from-scratch computation's, for impact count and DETP.
    const fs::path scene = writeDeformingScene("render", true);
    const fs::path out = testScratchDir("deformation-render-out");
    for (const char* estimator : {"impact-count", "detp"}) {
        SCOPED_TRACE(estimator);
        const std::string common = "render " + scene.string() + " --animation gltf --fps 48 --photons 20000 --no-exr --quiet --always-update " +
                                   "--estimator " + estimator;
        const fs::path inc = out / (std::string(estimator) + "-incremental"), full = out / (std::string(estimator) + "-full");
        const CommandResult a = runQsgi(common + " --out " + inc.string());
        ASSERT_EQ(a.exitCode, 0) << a.output;
        const CommandResult b = runQsgi(common + " --full-recompute --out " + full.string());
        ASSERT_EQ(b.exitCode, 0) << b.output;
        for (int frame = 0; frame <= 48; ++frame) {
            char name[32];
            std::snprintf(name, sizeof name, "frame_%04d.ply", frame);
            const std::string bytes = readFileBytes(inc / name);
            ASSERT_FALSE(bytes.empty()) << name;
            ASSERT_EQ(bytes, readFileBytes(full / name)) << name;
        }
        // The incremental frames retraced paths: the mesh was dynamic, not recomputed whole.
        const json timing = json::parse(readFileBytes(inc / "timing.json"));
        EXPECT_GT(timing["frames"][10]["paths_retraced"].get<int64_t>(), 0);
        EXPECT_LT(timing["frames"][10]["paths_retraced"].get<int64_t>(), 20000);
    }
}

TEST(Deformation, AMeshDeformingInOneRegionRetracesAndRecomputesOnlyNearIt) {
    // A 4 m sheet of 50×50 cells (2,601 vertices) under a lamp, with one morph target lifting a
    // central patch of 5×5 vertices (1 %) by 0.2 m, animated 0 → 1 over 1 s. The whole sheet is
    // dynamic geometry, but only the patch moves: the update must retrace the paths that met the
    // patch (or pass where it moves to) and recompute the discs near it, not the sheet's.
    testscenes::GltfWriter w;
    const int cells = 50;
    std::vector<float> positions, lift;
    std::vector<uint16_t> indices;
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            const float x = -2 + 4.0f * float(i) / cells, z = 2 - 4.0f * float(j) / cells;
            positions.insert(positions.end(), {x, 0, z});
            const bool patch = std::abs(i - cells / 2) <= 2 && std::abs(j - cells / 2) <= 2;
            lift.insert(lift.end(), {0, patch ? 0.2f : 0.0f, 0});
        }
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const uint16_t a = uint16_t(j * (cells + 1) + i), b = uint16_t(a + cells + 1);
            indices.insert(indices.end(), {a, uint16_t(a + 1), uint16_t(b + 1), a, uint16_t(b + 1), b});
        }
    const int p = w.accessor(positions, "VEC3"), idx = w.indices(indices), target = w.accessor(lift, "VEC3");
    w.doc["meshes"] = json::array({{{"weights", {0.0}}, {"primitives", json::array({{{"attributes", {{"POSITION", p}}},
        {"indices", idx}, {"targets", json::array({{{"POSITION", target}}})}}})}}});
    const int sheet = w.node({{"name", "Sheet"}, {"mesh", 0}});
    const int lamp = w.node({{"name", "Lamp"}, {"translation", {0, 1.5, 0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    w.doc["scenes"] = json::array({{{"nodes", {sheet, lamp}}}});
    w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    w.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({{{"type", "point"}, {"intensity", 30}}})}}}};
    const int times = w.accessor({0, 1}, "SCALAR"), weights = w.accessor({0, 1}, "SCALAR");
    w.doc["animations"] = json::array({{{"samplers", json::array({{{"input", times}, {"output", weights}}})},
        {"channels", json::array({{{"sampler", 0}, {"target", {{"node", sheet}, {"path", "weights"}}}}})}}});
    const fs::path dir = testScratchDir("deformation-region");
    w.write((dir / "sheet.gltf").string());

    const std::string common = "render " + (dir / "sheet.gltf").string() +
                               " --animation gltf --fps 4 --estimator detp --photons 40000 --no-exr --quiet";
    ASSERT_EQ(runQsgi(common + " --out " + (dir / "inc").string()).exitCode, 0);
    ASSERT_EQ(runQsgi(common + " --full-recompute --out " + (dir / "full").string()).exitCode, 0);
    const json timing = json::parse(readFileBytes(dir / "inc/timing.json"));
    for (int frame = 1; frame <= 4; ++frame) {
        SCOPED_TRACE("frame " + std::to_string(frame));
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d.ply", frame);
        EXPECT_EQ(readFileBytes(dir / "inc" / name), readFileBytes(dir / "full" / name));
        const json& f = timing["frames"][frame];
        // The patch is 1 % of the sheet (0.16 of its 16 m²): a few per cent of the paths meet it
        // or its neighbourhood; the sheet's other discs are left alone.
        EXPECT_GT(f["paths_retraced"].get<int64_t>(), 0);
        EXPECT_LT(f["paths_retraced"].get<int64_t>(), 40000 / 20);
        EXPECT_LT(f["vertices_recomputed"].get<int64_t>(), 2601 / 10);
    }
}

// A joint index names a joint of the skin even where its weight is 0 (glTF 2.0; issue 23): the
// strip's skin has 2 joints, and vertex 0 names joint 7 with weight 0.
// glTF 2.0 (§5.28): inverse bind matrices are affine. Only the last row is checked (a joint
// under a non-uniformly scaled parent legitimately has a sheared one).
TEST(Deformation, AnInverseBindMatrixWhoseLastRowIsNotAffineIsRefused) {
    Warnings warnings;
    try {
        loadGltfScene(writeDeformingScene("ibm-projective", false, 0, 2.0f).string(), warnings);
        ADD_FAILURE() << "a projective inverse bind matrix was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("skins[0].inverseBindMatrices"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("matrix 1"), std::string::npos) << e.what();
    }
}

// A node outside the default scene that reuses the rendered skinned mesh and its skin is
// checked in a scratch scene of its own (the real scene's skins are set aside: reusing their
// indices there read past the scratch scene's skins).
TEST(Deformation, AnUnrenderedNodeReusingTheRenderedSkinLoadsCleanly) {
    const fs::path file = writeDeformingScene("skin-reused", false);
    nlohmann::json doc = nlohmann::json::parse(readFileBytes(file));
    doc["nodes"].push_back({{"name", "Elsewhere"}, {"mesh", 0}, {"skin", 0}});
    std::ofstream(file.parent_path() / "skin-reused-orphan.gltf") << doc.dump();
    Warnings warnings;
    Scene scene;
    ASSERT_NO_THROW(scene = loadGltfScene((file.parent_path() / "skin-reused-orphan.gltf").string(), warnings));
    EXPECT_EQ(scene.skins.size(), 1u);
    for (const std::string& w : warnings.messages) EXPECT_EQ(w.find("rendered scene"), std::string::npos) << w;
}

// A joint scaled to zero hides what it alone holds (glTF's visibility, docs/design.md §3): the strip's
// vertices weighted wholly to Tip, not those it shares with Root (their blend, ½ I, is invertible).
TEST(Deformation, AJointScaledToZeroHidesTheVerticesItAloneHolds) {
    Warnings warnings;
    Scene scene = loadGltfScene(writeDeformingScene("joint-zero", false).string(), warnings);
    const MeshInstance& strip = scene.instances[0];
    std::vector<Transform> locals = scene.restLocals();
    locals[1] = locals[1] * Transform::fromTRS(Vec3d(0.0), {0, 0, 0, 1}, Vec3d(0.0));
    scene.applyPose(Pose(locals));
    for (uint32_t v = 0; v < 6; ++v) {
        const bool tipOnly = v == 2 || v == 5;
        EXPECT_EQ(bool(scene.vertexHidden[strip.firstVertex + v]), tipOnly) << v;
        EXPECT_TRUE(isFinite(scene.normals[strip.firstVertex + v]) && length(scene.normals[strip.firstVertex + v]) > 0.99f) << v;
    }
    scene.applyPose(scene.restPose());
    for (uint32_t v = 0; v < 6; ++v) EXPECT_FALSE(scene.vertexHidden[strip.firstVertex + v]) << v;
}

TEST(Deformation, AJointIndexBeyondTheSkinIsRefusedEvenWithWeightZero) {
    Warnings warnings;
    EXPECT_NO_THROW(loadGltfScene(writeDeformingScene("joints-valid", false, 1).string(), warnings));
    try {
        loadGltfScene(writeDeformingScene("joints-beyond", false, 7).string(), warnings);
        ADD_FAILURE() << "a joint index beyond the skin was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("JOINTS_0"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("names joint 7 of a skin with 2"), std::string::npos) << e.what();
    }
}
