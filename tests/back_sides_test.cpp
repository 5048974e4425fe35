// Both sides of a doubleSided surface (issue 57, lib/scene/back_sides.h): its back is lit as if the
// surface were duplicated with reversed winding and negated normals, and the inside of a closed
// doubleSided mesh stays dark and covered. Tolerances from the run-to-run noise measured in the
// same test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "output/ply_reader.h"
#include "output/ply_writer.h"
#include "output/radiosity_image.h"
#include "pipeline/frame_solver.h"
#include "scene/back_sides.h"
#include "test_support.h"

using namespace qsgi;

namespace {

// Gives instance `instance` a material of its own: albedo `albedo`, doubleSided as said.
void giveMaterial(Scene& s, size_t instance, Vec3f albedo, bool doubleSided) {
    Material m("sheet", albedo);
    m.doubleSided = doubleSided;
    s.materials.push_back(m);
    const uint32_t index = uint32_t(s.materials.size() - 1);
    const MeshInstance& inst = s.instances[instance];
    for (uint32_t t = inst.firstTriangle; t < inst.firstTriangle + inst.triangleCount; ++t) s.triangleMaterial[t] = index;
    for (uint32_t v = inst.firstVertex; v < inst.firstVertex + inst.vertexCount; ++v) s.vertexMaterial[v] = index;
}

FrameSolverSettings twoPassSettings(uint32_t seed) {
    FrameSolverSettings s;
    s.estimator.kind = EstimatorKind::ImpactCount;
    s.trace = TraceSettings{200000, seed, 32, EmissionAim{}, PhotonSampling{}};
    s.lighting.direct = DirectLighting::Exact;
    s.lighting.gatherRays = 128;
    s.update.fullRecompute = true;
    return s;
}

VertexRadiosity solve(Scene& scene, uint32_t seed) {
    const EmbreeDevice device;
    FrameSolver solver(scene, device, twoPassSettings(seed));
    return solver.solve(scene.restPose()).radiosity;
}

// The vertex of instance `instance` of `scene` at `p` (the sheets' grids are laid out in
// opposite orders).
uint32_t vertexAt(const Scene& scene, size_t instance, const Vec3f& p) {
    const MeshInstance& inst = scene.instances[instance];
    for (uint32_t v = inst.firstVertex; v < inst.firstVertex + inst.vertexCount; ++v)
        if (length(scene.positions[v] - p) < 1e-6f) return v;
    ADD_FAILURE() << "no vertex at " << p.x << ", " << p.y << ", " << p.z;
    return inst.firstVertex;
}

struct Difference {
    double rms = 0, mean = 0;  // relative to the mean of `b`
};
Difference relativeDifference(const std::vector<double>& a, const std::vector<double>& b) {
    double sum = 0, squares = 0, scale = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        sum += a[i] - b[i];
        squares += (a[i] - b[i]) * (a[i] - b[i]);
        scale += b[i];
    }
    const double n = double(a.size());
    scale /= n;
    return Difference{std::sqrt(squares / n) / scale, sum / n / scale};
}

}  // namespace

// A sheet 0.6 m over a floor, a point light between them: the sheet is lit from behind. Scene A:
// the sheet faces up and is doubleSided, so its lit side is its back. Scene B, the mirror: the
// same sheet single-sided, facing down. A's back values must equal B's front values, and A's
// floor B's floor (the sheet's back reflects as B's front does), within the noise of the
// estimates: measured here as B against B with another seed. An estimate of RMS over n ≈ 80
// vertices is itself known to about 1/√(2n) ≈ 8 %, so 1.5 × the seed-to-seed RMS is six of its
// standard deviations; the mean difference likewise within 4 × the seed-to-seed RMS / √n. The
// sheet's top, which nothing lights, is 0 in A.
TEST(BackSides, ADoubleSidedSheetLitFromBehindEqualsItsMirror) {
    const Vec3f albedo(0.6f, 0.5f, 0.4f);
    Scene a = testscenes::plateUnderSheet(1.0f, 16, 0.5f, 8, 0.6f, true, Vec3f(0.5f));
    giveMaterial(a, 1, albedo, true);
    testscenes::addPointLight(a, Vec3f(0.1f, 0.3f, 0.05f), Vec3f(1.0f));
    addBackSides(a);
    ASSERT_TRUE(a.backSides.has_value());
    ASSERT_EQ(a.instances.size(), 3u);
    EXPECT_EQ(a.instances[2].backOf, 1);
    Scene b = testscenes::plateUnderSheet(1.0f, 16, 0.5f, 8, 0.6f, false, Vec3f(0.5f));
    giveMaterial(b, 1, albedo, false);
    testscenes::addPointLight(b, Vec3f(0.1f, 0.3f, 0.05f), Vec3f(1.0f));
    addBackSides(b);
    EXPECT_FALSE(b.backSides.has_value());  // nothing doubleSided: the scene is as it was

    const VertexRadiosity ra = solve(a, 7), rb = solve(b, 7), rbOther = solve(b, 8);
    std::vector<double> sheetA, sheetB, sheetBOther, floorA, floorB, floorBOther;
    const MeshInstance& sheet = a.instances[1];
    for (uint32_t v = sheet.firstVertex; v < sheet.firstVertex + sheet.vertexCount; ++v) {
        const uint32_t back = a.backSides->backVertex[v];
        ASSERT_NE(back, Scene::BackSides::kNone);
        EXPECT_EQ(a.positions[back], a.positions[v]);
        EXPECT_EQ(a.normals[back], -a.normals[v]);
        EXPECT_EQ(ra.irradiance[v], Vec3f(0.0f)) << "the sheet's top, vertex " << v;
        const uint32_t mirror = vertexAt(b, 1, a.positions[v]);
        for (int c = 0; c < 3; ++c) {
            sheetA.push_back(ra.radiosity[back][c]);
            sheetB.push_back(rb.radiosity[mirror][c]);
            sheetBOther.push_back(rbOther.radiosity[mirror][c]);
        }
    }
    const MeshInstance& floor = a.instances[0];
    for (uint32_t v = floor.firstVertex; v < floor.firstVertex + floor.vertexCount; ++v) {
        const uint32_t mirror = vertexAt(b, 0, a.positions[v]);
        for (int c = 0; c < 3; ++c) {
            floorA.push_back(ra.irradiance[v][c]);
            floorB.push_back(rb.irradiance[mirror][c]);
            floorBOther.push_back(rbOther.irradiance[mirror][c]);
        }
    }
    auto expectSame = [](const char* what, const std::vector<double>& x, const std::vector<double>& y,
                         const std::vector<double>& yOther) {
        const Difference noise = relativeDifference(yOther, y), d = relativeDifference(x, y);
        const double n = double(x.size()) / 3;
        std::printf("%s: relative RMS %.5f, mean %+.5f (seed to seed %.5f)\n", what, d.rms, d.mean, noise.rms);
        EXPECT_GT(noise.rms, 0) << what << ": two seeds gave the same values";
        EXPECT_LT(d.rms, 1.5 * noise.rms + 1e-6) << what << " (the seed-to-seed RMS is " << noise.rms << ")";
        EXPECT_LT(std::fabs(d.mean), 4 * noise.rms / std::sqrt(n) + 1e-6) << what << " (the seed-to-seed RMS is " << noise.rms << ")";
    };
    expectSame("the sheet's back against its mirror's front", sheetA, sheetB, sheetBOther);
    expectSame("the floor under the doubleSided sheet against its mirror's", floorA, floorB, floorBOther);
}

// A closed doubleSided sphere (exporters mark materials doubleSided by default) under a point
// light: its inside is its back, which no light reaches.
//  - Opaque, it closes a volume no light enters: no back side is made (it would cost as much as the
//    front and be 0), and the outputs' back values are 0.
//  - Cut out by an alpha MASK that happens to keep every point (so light could pass in general),
//    its back sides are made: every one is covered (the cover test is geometric: a ray meeting a
//    back side meets the back of the surface) and reads 0.
// Either way the front is lit as the single-sided sphere's, to the bit: the light reaches it by
// the same rays, and the photons' bounces off its outside go to infinity alike.
TEST(BackSides, TheInsideOfAClosedDoubleSidedMeshIsCoveredAndDark) {
    for (const bool cutOut : {false, true}) {
        SCOPED_TRACE(cutOut ? "an alpha-MASK sphere" : "an opaque sphere");
        Scene s = testscenes::closedSphere(0.5f, 3, Vec3f(0.7f), false);
        giveMaterial(s, 0, Vec3f(0.7f), true);
        if (cutOut) s.materials.back().alphaMode = AlphaMode::Mask;  // alpha 1 everywhere: nothing is cut
        testscenes::addPointLight(s, Vec3f(2.0f, 0.5f, 0.0f), Vec3f(4.0f));
        Scene single = s;
        single.materials.back().doubleSided = false;
        addBackSides(s);
        ASSERT_TRUE(s.backSides.has_value());
        const EmbreeDevice device;
        FrameSolver solver(s, device, twoPassSettings(3));
        const VertexRadiosity r = solver.solve(s.restPose()).radiosity;
        const VertexRadiosity alone = solve(single, 3);
        ASSERT_EQ(s.frontVertexCount(), single.vertexCount());
        for (uint32_t v = 0; v < s.frontVertexCount(); ++v) EXPECT_EQ(r.irradiance[v], alone.irradiance[v]) << "vertex " << v;
        if (!cutOut) {
            EXPECT_EQ(s.vertexCount(), single.vertexCount()) << "no back side is made for a sealed inside";
            for (uint32_t back : s.backSides->backVertex) EXPECT_EQ(back, Scene::BackSides::kNone);
            const std::string ply = encodeVertexRadiosityPly(s, r, PreviewTonemap{});
            EXPECT_NE(ply.find("property float back_radiosity_r"), std::string::npos) << "the outputs carry the back values";
            continue;
        }
        const std::vector<uint8_t> covered = solver.coveredVertices();
        ASSERT_EQ(covered.size(), s.vertexCount());
        size_t lit = 0;
        for (uint32_t v = 0; v < s.frontVertexCount(); ++v) {
            const uint32_t back = s.backSides->backVertex[v];
            ASSERT_NE(back, Scene::BackSides::kNone);
            EXPECT_TRUE(covered[back]) << "back vertex " << back;
            EXPECT_EQ(r.irradiance[back], Vec3f(0.0f)) << "back vertex " << back;
            EXPECT_FALSE(covered[v]) << "front vertex " << v;
            lit += r.irradiance[v].x > 0;
        }
        EXPECT_GT(lit, s.frontVertexCount() / 3);
    }
}

// A doubleSided tube open at both ends (testscenes::cubeBesideTube) under a point light: deep
// inside, its back sides' cover rays meet only its back faces, so they are dark — exactly 0 (they
// cast no shadow ray, and no gather ray beyond their cover rays: Incremental.ACubeSlidingInto…
// checks that an update finds the same). Near the open ends rays leave the tube: lit. With the
// cube slid inside, some cover rays meet its faces: fewer are dark.
TEST(BackSides, TheDarkInsideOfATubeCastsItsCoverRaysAlone) {
    Scene s = testscenes::cubeBesideTube(Vec3f(0.7f));
    testscenes::addPointLight(s, Vec3f(0.4f, 2.0f, 0.3f), Vec3f(20.0f));
    addBackSides(s);
    ASSERT_TRUE(s.backSides.has_value());
    const int cube = 1;  // node "Cube"
    ASSERT_EQ(s.nodes[size_t(cube)].name, "Cube");
    s.markDynamic({cube});
    FrameSolverSettings settings = twoPassSettings(5);
    settings.lighting.gatherRays = 64;
    const EmbreeDevice device;
    size_t darkOutside = 0;
    for (const double slide : {0.0, 0.9}) {
        SCOPED_TRACE(slide == 0 ? "the cube outside" : "the cube inside");
        FrameSolver solver(s, device, settings);
        std::vector<Transform> locals = s.restLocals();
        locals[size_t(cube)] = Transform::fromTRS(Vec3d(slide, 0, 0), {0, 0, 0, 1}, Vec3d(1.0)) * locals[size_t(cube)];
        const VertexRadiosity r = solver.solve(Pose(locals)).radiosity;
        const std::vector<uint8_t> covered = solver.coveredVertices();
        size_t dark = 0, litBack = 0;
        for (uint32_t v = uint32_t(s.frontVertexCount()); v < s.vertexCount(); ++v) {
            if (covered[v]) {
                ++dark;
                EXPECT_EQ(r.irradiance[v], Vec3f(0.0f)) << "dark back vertex " << v;
            } else {
                litBack += r.irradiance[v].x > 0;
            }
        }
        EXPECT_GT(dark, (s.vertexCount() - s.frontVertexCount()) / 8) << "the inside is dark (its middle: 123 of 588 measured)";
        EXPECT_GT(litBack, 0u) << "the open ends are lit";
        if (slide == 0) darkOutside = dark;
        else EXPECT_LT(dark, darkOutside) << "the cube's faces meet cover rays inside the tube";
        std::printf("%s: %zu of %zu back vertices dark, %zu lit\n", slide == 0 ? "cube outside" : "cube inside", dark,
                    s.vertexCount() - s.frontVertexCount(), litBack);
    }
}

// The command keeps the back sides through the least-squares vertex fit, whose sampling mesh is a
// refined copy of the output mesh: both get back sides on the same instances (the fit pairs them),
// and the frame's PLY carries the doubleSided card's back, which faces the ceiling panel: lit.
TEST(BackSides, TheVertexFitSolvesAndWritesTheBackSides) {
    const std::filesystem::path out = testScratchDir("back-sides-fit");
    const CommandResult run = runQsgi("render " + (sourceDir() / "tests/data/materials_room/materials_room.gltf").string() +
                                      " --sky 1,1,1 --vertex-fit least-squares --photons 20000" + kCheapSecondPass +
                                      " --quiet --no-exr --out " + out.string());
    ASSERT_EQ(run.exitCode, 0) << run.output;
    const VertexRadiosityPly ply = readVertexRadiosityPly((out / "frame_0000.ply").string());
    ASSERT_EQ(ply.backRadiosity.size(), ply.radiosity.size());
    size_t lit = 0;
    for (const Vec3f& b : ply.backRadiosity) lit += maxComponent(b) > 0;
    EXPECT_GT(lit, 50u) << "the card's back (13 x 13 cells, half of them cut out) is lit";
}

// The camera shows the side it sees: looking up at the doubleSided sheet from under it, the back
// side's values; looking down on it, the front's (an irradiance of 3 on every back vertex and 1
// on every front one, so B/π is ρ·3/π and ρ/π, exactly).
TEST(BackSides, TheCameraShowsTheSideItSees) {
    const Vec3f albedo(0.6f, 0.5f, 0.4f);
    Scene s = testscenes::plateUnderSheet(1.0f, 4, 0.5f, 4, 0.6f, true, Vec3f(0.5f));
    giveMaterial(s, 1, albedo, true);
    addBackSides(s);
    const EmbreeDevice device;
    const SceneBvh bvh(device, s);
    VertexRadiosity solution;
    solution.irradiance.assign(s.vertexCount(), Vec3f(1.0f));
    for (uint32_t v = uint32_t(s.frontVertexCount()); v < s.vertexCount(); ++v) solution.irradiance[v] = Vec3f(3.0f);
    computeRadiosity(s, solution);
    for (const bool fromBelow : {true, false}) {
        Camera camera;
        camera.projection = Projection::Orthographic;
        camera.position = Vec3f(Vec3d(0, fromBelow ? 0.3 : 2.0, 0) - s.worldOrigin);  // scene space is re-centred
        camera.forward = Vec3f(0, fromBelow ? 1.0f : -1.0f, 0);
        camera.up = Vec3f(0, 0, -1);
        camera.ymag = 0.4f;  // inside the sheet's 1 m
        ImageSettings settings;
        settings.width = settings.height = 8;
        const RgbImage image = renderRadiosityImage(s, bvh, solution, camera, settings);
        const float expected = albedo.x * (fromBelow ? 3.0f : 1.0f) / float(M_PI);
        for (int p = 0; p < settings.width * settings.height; ++p)
            EXPECT_NEAR(image.pixels[3 * size_t(p)], expected, 1e-6f) << (fromBelow ? "from below" : "from above") << ", pixel " << p;
    }
}
