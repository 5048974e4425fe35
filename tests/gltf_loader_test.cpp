// The loader against real files from other projects (../shared/data/gltf-samples, SOURCES.md
// gives the expected flattened triangle counts) and against the scenes shipped in data/.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>

#include "scene/gltf_loader.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

// "scene" triangle counts from ../shared/data/gltf-samples/SOURCES.md.
const std::map<std::string, size_t> kExpectedTriangles = {
    {"valid/2CylinderEngine/2CylinderEngine.glb", 121496},
    {"valid/BoxTextured/BoxTextured.gltf", 12},
    {"valid/BoxTextured-Embedded/BoxTextured.gltf", 12},
    {"valid/BoxTextured-Binary/BoxTextured.glb", 12},
    {"valid/Cameras/Cameras.gltf", 2},
    {"valid/AnimatedMorphCube/AnimatedMorphCube.gltf", 12},
    {"valid/SimpleMorph/SimpleMorph.gltf", 1},
    {"valid/ClearCoatTest/ClearCoatTest.gltf", 37116},
    {"valid/TextureTransformTest/TextureTransformTest.gltf", 24},
    {"valid/simple_skin/simple_skin.gltf", 8},
    {"valid/simple_skin/quad_skin.glb", 2},
    {"valid/Cube/Cube.gltf", 12},
    {"valid/box01/box01.glb", 12},
    {"models/Box/glTF/Box.gltf", 12},
    {"models/Box/glTF-Binary/Box.glb", 12},
    {"models/Box/glTF-Embedded/Box.gltf", 12},
    {"models/BoxInterleaved/glTF-Binary/BoxInterleaved.glb", 12},
    {"models/BoxVertexColors/glTF-Binary/BoxVertexColors.glb", 12},
    {"models/Triangle/glTF/Triangle.gltf", 1},
    {"models/Duck/glTF/Duck.gltf", 4212},
    {"models/Duck/glTF-Binary/Duck.glb", 4212},
    {"models/CesiumMilkTruck/glTF/CesiumMilkTruck.gltf", 3624},
    {"models/FlightHelmet/glTF/FlightHelmet.gltf", 94722},
    {"models/Lantern/glTF/Lantern.gltf", 5394},
    {"models/ToyCar/glTF/ToyCar.gltf", 108936},
    {"models/BoxAnimated/glTF-Binary/BoxAnimated.glb", 254},
    {"models/BoxAnimated/glTF-Embedded/BoxAnimated.gltf", 254},
    {"models/AnimatedCube/glTF/AnimatedCube.gltf", 12},
    {"models/AnimatedTriangle/glTF-Embedded/AnimatedTriangle.gltf", 1},
    {"models/InterpolationTest/glTF/InterpolationTest.gltf", 110},
    {"models/EmissiveStrengthTest/glTF-Binary/EmissiveStrengthTest.glb", 90},
    {"models/MultiUVTest/glTF/MultiUVTest.gltf", 12},
    {"models/SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf", 12},
    {"models/SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf", 12},
    {"models/MultipleScenes/glTF-Embedded/MultipleScenes.gltf", 2},
    {"models/PlayCanvasLights/glTF-Binary/Lights.glb", 12},
    {"models/PlayCanvasGeometryCameraLight/glTF-Binary/geometry-camera-light.glb", 14},
    {"models/DracoSphereLights/glTF/sphere_lights.gltf", 224},
    {"models/NegativeScaleQuad/glTF-Embedded/negativeScaleQuad.gltf", 12},
};

// Mesh_PrimitiveMode README: points and lines (00-03, 07-10) give none; strips, fans, triangles 2.
size_t primitiveModeTriangles(int model) { return (model <= 3 || (model >= 7 && model <= 10)) ? 0 : 2; }

// ../shared sits beside the repository in CI but not in a user's clone; tests that need its
// samples skip with this reason there.
constexpr const char* kNoSharedSamples = "../shared/data/gltf-samples is absent (only beside the repository in CI)";
fs::path samplesDir() { return sharedDir() / "data" / "gltf-samples"; }

bool isGltf(const fs::path& p) { return p.extension() == ".gltf" || p.extension() == ".glb"; }

}  // namespace

TEST(GltfLoader, EveryValidAndModelSampleLoadsWithTheDocumentedTriangleCount) {
    const auto samples = samplesDir();
    if (!fs::exists(samples)) GTEST_SKIP() << kNoSharedSamples;
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
