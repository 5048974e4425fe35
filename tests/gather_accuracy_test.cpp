// Accuracy of the second pass (exact direct light and the final gather, docs/design.md §5.1) against
// the independent references of tests/reference_accuracy_test.cpp (Mitsuba 3, 16384 paths and
// emitter samples per vertex, whose own noise is about 0.7 % relative), at the renderer's defaults:
// 10^6 photons, 64 direct samples, 256 gather rays.
//
// 1. Every estimator under the gather stays within bounds set by that file's rule: the error at
//    seed 1 plus three times its change between seeds 1 and 2, and at least 0.005 (the printed
//    figures' last digit rounded up). Against the photons alone (reference_accuracy_test.cpp) the
//    bounds fell: data/cornell overall 0.045–0.17 → 0.015–0.018, interior 0.04–0.18 → 0.0075;
//    the ceiling panel 0.038–0.215 → 0.017–0.018; the corner 0.028–0.093 → 0.005–0.007. The
//    ceiling above the panel (a 1 cm gap, its reference 1.5·10⁻⁴ W/m², 300× darker than the room)
//    stays several times its reference, the panel's top interpolated from its corners' first pass. The vertices
//    where two surfaces touch (a block standing on the floor, a wall's foot: AccuracyReport::contact)
//    are reported as a region of their own, and bounded the same way: their reference is the
//    limit of two surfaces at once, and both renderers disagree most there.
// 2. The error falls as the gather rays and the photons grow, in every region: from M = 64 to 256
//    at 10^6 photons, and from 10^5 to 10^6 photons at M = 256 — each fall required to exceed
//    minus twice the seed-to-seed spread of the two errors (a region whose error has reached the
//    reference's own noise may stay level, not rise).
// 3. The open box under a uniform sky (tests/scenes/open_box_sky.gltf, no light of its own): the sky's
//    direct light by 64 cosine-distributed shadow rays a vertex, the gather over sky photons. Its
//    interior error, 2.1 % at every estimator and seed, is the sky's direct-light sampling (half a
//    floor vertex's hemisphere is wall): --direct-samples lowers it.
// 4. Over the surface (issue 47), where a surface reference exists (data/cornell, the ceiling panel:
//    tests/reference/*_surface.ply, 10,000 points by area, 4096 paths each, noise about 0.7 %): the
//    irradiance interpolated across each triangle at those points, overall, in the contact band
//    (within the radius of another piece of surface: the block's foot, the ceiling round the panel)
//    and inside, bounded by the same rule (measured after issue 47's covered-vertex fill).
// QSGI_REFERENCE_SEED=2 runs the bounds' cases at seed 2, to measure the spread they rest on. The
// sanitizer run (scripts/test-sanitizers.sh) leaves these statistical tests out, as ReferenceAccuracy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include "estimate/accuracy.h"
#include "estimate/surface_accuracy.h"
#include "output/ply_reader.h"
#include "pipeline/frame_solver.h"
#include "scene/gltf_loader.h"
#include "test_support.h"

using namespace qsgi;

namespace {

struct Errors {
    AccuracyReport report;
    ErrorStats abovePanel;  // the ceiling above the ceiling panel's light (ceiling_panel only)
    // Over the surface (issue 47): irradiance interpolated at the surface reference's points, where
    // the scene has one (tests/reference/*_surface.ply); points 0 without.
    SurfaceAccuracyReport surface;
};

// Frame 0 of the scene from scratch, at the given settings (the radius is the reference tests').
Errors measure(const std::string& scenePath, const VertexRadiosityPly& reference, EstimatorKind kind, DetpBoundary rule,
               uint64_t photons, uint32_t gatherRays, uint64_t seed, const SurfaceReferencePly* surface = nullptr) {
    Scene scene = loadReferenceScene(scenePath);
    EXPECT_EQ(reference.positions.size(), scene.vertexCount());
    const EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator.kind = kind;
    s.estimator.detp.boundary = rule;
    s.estimator.radius = 0.05f;
    s.estimator.photonMap.k = 50;
    s.trace.photons = photons;
    s.trace.seed = seed;
    s.lighting.direct = DirectLighting::Exact;
    s.lighting.directSamples = 64;
    s.lighting.gatherRays = gatherRays;
    s.update.fullRecompute = true;
    FrameSolver solver(scene, device, s);
    const VertexRadiosity& result = solver.solve(scene.restPose(), false).radiosity;
    Errors e;
    e.report = compareSolutions(reference.positions, reference.normals, reference.triangles, result.radiosity,
                                reference.radiosity, 0.05f);
    std::vector<bool> above(scene.vertexCount(), false);
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3f& p = reference.positions[v];
        above[v] = p.y == 2.0f && std::fabs(p.x) < 0.25f && std::fabs(p.z) < 0.25f;
    }
    e.abovePanel = errorStats(result.radiosity, reference.radiosity, above);
    if (surface)
        e.surface = compareOverSurface(reference.positions, reference.normals, reference.triangles, result.irradiance,
                                       surface->points, 0.05f);
    return e;
}

// The scene's surface reference (its vertex reference's name with _surface), if it has one.
std::optional<SurfaceReferencePly> readSurfaceReference(const char* file) {
    std::string name = file;
    name.insert(name.rfind(".ply"), "_surface");
    const std::filesystem::path path = sourceDir() / "tests/reference" / name;
    if (!std::filesystem::exists(path)) return std::nullopt;
    return readSurfaceReferencePly(path.string());
}

VertexRadiosityPly readReference(const char* file) {
    return readVertexRadiosityPly((sourceDir() / "tests/reference" / file).string());
}

struct Bound {
    const char* estimator;
    double allRms, edgeRms, nearRms, interiorRms, contactRms, abovePanelRms;  // 0: not checked
    double surfaceRms, surfaceContactRms, surfaceInteriorRms;  // over the surface; 0: not checked
};

struct Case {
    const char* scene;
    const char* reference;
    Bound bounds[4];  // impact count, photon map (k = 50), DETP clip, DETP linear
};

const std::pair<EstimatorKind, DetpBoundary> kEstimators[4] = {{EstimatorKind::ImpactCount, DetpBoundary::Clip},
                                                               {EstimatorKind::PhotonMap, DetpBoundary::Clip},
                                                               {EstimatorKind::Detp, DetpBoundary::Clip},
                                                               {EstimatorKind::Detp, DetpBoundary::Linear}};

void print(const char* scene, const char* what, uint64_t seed, const Errors& e) {
    std::printf("%s seed %llu, %s: all %.4f | edge %.4f | near %.4f | interior %.4f | contact %.4f (%zu) | above panel %.4f\n",
                scene, static_cast<unsigned long long>(seed), what, e.report.all.relativeRms, e.report.edge.relativeRms,
                e.report.nearEdge.relativeRms, e.report.interior.relativeRms, e.report.contact.relativeRms,
                e.report.contact.vertices, e.abovePanel.relativeRms);
    if (e.surface.all.points > 0)
        std::printf("%s seed %llu, %s, over the surface: all %.4f (without the reference's noise %.4f) | contact %.4f | "
                    "edge %.4f | interior %.4f (%.4f)\n",
                    scene, static_cast<unsigned long long>(seed), what, e.surface.all.relativeRms, e.surface.all.withoutNoise,
                    e.surface.contact.relativeRms, e.surface.edge.relativeRms, e.surface.interior.relativeRms,
                    e.surface.interior.withoutNoise);
}

}  // namespace

class GatherAccuracy : public ::testing::TestWithParam<Case> {};

TEST_P(GatherAccuracy, EveryEstimatorWithTheGatherStaysWithinItsMeasuredError) {
    const Case& c = GetParam();
    const VertexRadiosityPly reference = readReference(c.reference);
    const std::optional<SurfaceReferencePly> surface = readSurfaceReference(c.reference);
    const char* seedText = std::getenv("QSGI_REFERENCE_SEED");
    const uint64_t seed = seedText ? std::strtoull(seedText, nullptr, 10) : 1;
    const uint64_t photons = 1000000;
    for (int i = 0; i < 4; ++i) {
        const Bound& b = c.bounds[i];
        const Errors e = measure(c.scene, reference, kEstimators[i].first, kEstimators[i].second, photons, 256, seed,
                                 surface ? &*surface : nullptr);
        print(c.scene, b.estimator, seed, e);
        EXPECT_LE(e.report.all.relativeRms, b.allRms) << b.estimator;
        EXPECT_LE(e.report.edge.relativeRms, b.edgeRms) << b.estimator;
        // A bounded region must hold vertices: an empty one has an RMS of 0, which passes any bound.
        if (b.nearRms > 0) {
            EXPECT_GT(e.report.nearEdge.vertices, 0u) << b.estimator << ": no vertex near an edge to bound";
            EXPECT_LE(e.report.nearEdge.relativeRms, b.nearRms) << b.estimator;
        }
        EXPECT_LE(e.report.interior.relativeRms, b.interiorRms) << b.estimator;
        if (b.contactRms > 0) {
            EXPECT_GT(e.report.contact.vertices, 0u) << b.estimator << ": no contact vertex to bound";
            EXPECT_LE(e.report.contact.relativeRms, b.contactRms) << b.estimator;
        }
        if (b.abovePanelRms > 0) {
            EXPECT_GT(e.abovePanel.vertices, 0u) << b.estimator << ": no ceiling vertex above the panel to bound";
            EXPECT_LE(e.abovePanel.relativeRms, b.abovePanelRms) << b.estimator;
        }
        if (b.surfaceRms > 0) {
            ASSERT_TRUE(surface) << "a bound over the surface needs the scene's surface reference";
            EXPECT_LE(e.surface.all.relativeRms, b.surfaceRms) << b.estimator << ", over the surface";
            EXPECT_LE(e.surface.contact.relativeRms, b.surfaceContactRms) << b.estimator << ", over the surface, contact band";
            EXPECT_LE(e.surface.interior.relativeRms, b.surfaceInteriorRms) << b.estimator << ", over the surface, interior";
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, GatherAccuracy,
    ::testing::Values(Case{"data/cornell/cornell.gltf",
                           "cornell_f0000.ply",
                           {{"impact count", 0.0154, 0.0145, 0.0732, 0.00755, 0.731, 0, 0.0203, 0.2387, 0.0086},
                            {"photon map", 0.0177, 0.0135, 0.0922, 0.00765, 0.904, 0, 0.0206, 0.2377, 0.0086},
                            {"DETP clip", 0.0147, 0.00995, 0.0738, 0.00745, 0.73, 0, 0.0202, 0.2345, 0.0083},
                            {"DETP linear", 0.0173, 0.015, 0.0896, 0.00785, 0.864, 0, 0.0204, 0.2375, 0.0086}}},
                      Case{"tests/scenes/ceiling_panel/ceiling_panel.gltf",
                           "ceiling_panel_f0000.ply",
                           {{"impact count", 0.0172, 0.013, 0.209, 0.00765, 0.604, 16, 0.0255, 0.3113, 0.0104},
                            {"photon map", 0.017, 0.017, 0.188, 0.00785, 0.605, 9.3, 0.0283, 0.3553, 0.0111},
                            {"DETP clip", 0.0175, 0.0126, 0.205, 0.00985, 0.6, 8.59, 0.027, 0.334, 0.0107},
                            {"DETP linear", 0.0178, 0.0148, 0.207, 0.00985, 0.603, 8.58, 0.028, 0.3358, 0.0104}}},
                      Case{"tests/scenes/corner_point_light.gltf",
                           "corner_point_light_f0000.ply",
                           // No vertex lies near an edge or at a contact (r = 0.05): those two are 0.
                           {{"impact count", 0.00505, 0.0109, 0, 0.005, 0, 0, 0, 0, 0},
                            {"photon map", 0.00625, 0.0199, 0, 0.00545, 0, 0, 0, 0, 0},
                            {"DETP clip", 0.00515, 0.0114, 0, 0.005, 0, 0, 0, 0, 0},
                            {"DETP linear", 0.00665, 0.0211, 0, 0.005, 0, 0, 0, 0, 0}}},
                      Case{"tests/scenes/open_box_sky.gltf",
                           "open_box_sky_f0000.ply",
                           {{"impact count", 0.0215, 0.0232, 0.079, 0.0209, 0.0305, 0, 0, 0, 0},
                            {"photon map", 0.0219, 0.0254, 0.082, 0.0209, 0.0328, 0, 0, 0, 0},
                            {"DETP clip", 0.0219, 0.0255, 0.081, 0.0209, 0.0329, 0, 0, 0, 0},
                            {"DETP linear", 0.0233, 0.0295, 0.081, 0.0207, 0.0321, 0, 0, 0, 0}}}),
    [](const ::testing::TestParamInfo<Case>& info) {
        const std::string file = info.param.reference;
        return file.substr(0, file.find("_f0000"));
    });

// The error falls with M and with the photons (impact count, the default estimator), region by
// region, within twice the seed-to-seed spread.
TEST(GatherAccuracy, ErrorFallsWithGatherRaysAndPhotonsInEveryRegion) {
    for (const auto& [scene, file] : {std::pair<const char*, const char*>{"data/cornell/cornell.gltf", "cornell_f0000.ply"},
                                      {"tests/scenes/ceiling_panel/ceiling_panel.gltf", "ceiling_panel_f0000.ply"}}) {
        const VertexRadiosityPly reference = readReference(file);
        // [seed][setting]: (10^6, M = 64), (10^6, M = 256), (10^5, M = 256)
        Errors e[2][3];
        for (uint64_t seed : {1, 2}) {
            e[seed - 1][0] = measure(scene, reference, EstimatorKind::ImpactCount, DetpBoundary::Clip, 1000000, 64, seed);
            e[seed - 1][1] = measure(scene, reference, EstimatorKind::ImpactCount, DetpBoundary::Clip, 1000000, 256, seed);
            e[seed - 1][2] = measure(scene, reference, EstimatorKind::ImpactCount, DetpBoundary::Clip, 100000, 256, seed);
            print(scene, "M = 64", seed, e[seed - 1][0]);
            print(scene, "M = 256", seed, e[seed - 1][1]);
            print(scene, "10^5 photons, M = 256", seed, e[seed - 1][2]);
        }
        const std::pair<const char*, ErrorStats AccuracyReport::*> regions[] = {
            {"all", &AccuracyReport::all},           {"edge", &AccuracyReport::edge},
            {"near edge", &AccuracyReport::nearEdge}, {"interior", &AccuracyReport::interior},
            {"contact", &AccuracyReport::contact}};
        for (const auto& [name, region] : regions) {
            auto rms = [&](int seed, int setting) { return (e[seed][setting].report.*region).relativeRms; };
            // Both scenes have vertices in every region: an empty one would pass with nothing compared.
            ASSERT_GT((e[0][1].report.*region).vertices, 0u) << scene << ", " << name;
            // (coarser − finer) at each seed; the spread is how much the two seeds' falls differ.
            for (const auto& [coarse, what] : {std::pair<int, const char*>{0, "M 64 -> 256"}, {2, "10^5 -> 10^6 photons"}}) {
                const double fall1 = rms(0, coarse) - rms(0, 1), fall2 = rms(1, coarse) - rms(1, 1);
                const double spread = std::fabs(rms(0, coarse) - rms(1, coarse)) + std::fabs(rms(0, 1) - rms(1, 1));
                EXPECT_GT(0.5 * (fall1 + fall2), -2 * spread) << scene << ", " << name << ": " << what;
                // Overall and inside, where the gather's own noise is most of the error, four times
                // the rays must lower it outright.
                if (coarse == 0 && (std::string(name) == "all" || std::string(name) == "interior")) {
                    EXPECT_GT(std::min(fall1, fall2), 0.0) << scene << ", " << name << ": " << what;
                }
            }
        }
    }
}
