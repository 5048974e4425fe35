// Accuracy against an independent renderer (issue 7): tests/reference/*.ply hold per-vertex
// radiosity rendered with Mitsuba 3 by scripts/reference.py (16384 paths + emitter samples per
// vertex). Each estimator's error per region — on an edge, within one radius of one, the rest,
// and for the ceiling-panel scene the ceiling above the panel — must stay within bounds set from
// measured values: the error at seed 1 plus a margin of three times its change between seeds 1
// and 2 (the noise), and at least 0.005. A regression in any estimator's definition fails here.
// The bounds were set again under the Sobol sampler (issue 20), whose photons lowered most errors,
// and each kept at its earlier (random-photon) value where that was the tighter one. The corner
// scene's near-edge region is empty (its grid spacing, 0.083, exceeds the radius): its near-edge
// bound is not checked.
// The open box under a sky (issue 35) has no light of its own: it and its reference are lit by a
// uniform sky of radiance 1 (loadReferenceScene), whose photons come from outside the scene; its
// bounds were set by the same rule (seeds 1 and 2 measured with the sky's first commit).
// SCENES ARE FROZEN WITH THEIR REFERENCES: regenerate both (scripts/reference.py) if a scene changes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "estimate/accuracy.h"
#include "estimate/estimator.h"
#include "output/ply_reader.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "trace/photon_tracer.h"

using namespace qsgi;

namespace {

struct Bound {
    const char* estimator;
    double allRms, edgeBias, nearBias, interiorRms, regionBias;  // |bias| and RMS ceilings
};

struct Case {
    const char* scene;      // glTF under the repository
    const char* reference;  // PLY under tests/reference
    // Bounds per estimator: impact count, photon map (k = 50), DETP clip, DETP linear.
    Bound bounds[4];
};

struct Figures {
    AccuracyReport report;
    ErrorStats region;  // ceiling above the panel (ceiling_panel only)
};

Figures measure(const Scene& scene, const RayCache& cache, const VertexRadiosityPly& reference, EstimatorKind kind,
                DetpBoundary rule, float radius) {
    EstimatorSettings s;
    s.kind = kind;
    s.detp.boundary = rule;
    s.radius = radius;
    s.photonMap.k = 50;
    const VertexRadiosity result = estimateWith(scene, cache, s);
    Figures f;
    f.report = compareSolutions(reference.positions, reference.normals, reference.triangles, result.radiosity,
                                reference.radiosity, radius);
    std::vector<bool> above(scene.vertexCount(), false);
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3f& p = reference.positions[v];
        above[v] = p.y == 2.0f && std::fabs(p.x) < 0.25f && std::fabs(p.z) < 0.25f;
    }
    f.region = errorStats(result.radiosity, reference.radiosity, above);
    return f;
}

}  // namespace

// The test's name: the reference's file name without "_f0000.ply".
std::string caseName(const Case& c) {
    const std::string file = c.reference;
    return file.substr(0, file.find("_f0000"));
}

class ReferenceAccuracy : public ::testing::TestWithParam<Case> {};

TEST_P(ReferenceAccuracy, EveryEstimatorStaysWithinItsMeasuredError) {
    const Case& c = GetParam();
    const Scene scene = loadReferenceScene(c.scene);
    const VertexRadiosityPly reference = readVertexRadiosityPly((sourceDir() / "tests/reference" / c.reference).string());
    ASSERT_EQ(reference.positions.size(), scene.vertexCount());
    const float radius = 0.05f;
    // QSGI_REFERENCE_SEED lets a developer measure the seed-to-seed spread the bounds rest on.
    const char* seedText = std::getenv("QSGI_REFERENCE_SEED");
    const uint64_t seed = seedText ? std::strtoull(seedText, nullptr, 10) : 1;
    const RayCache cache = traceScene(scene, 1000000, seed);
    const std::pair<EstimatorKind, DetpBoundary> estimators[4] = {{EstimatorKind::ImpactCount, DetpBoundary::Clip},
                                                                   {EstimatorKind::PhotonMap, DetpBoundary::Clip},
                                                                   {EstimatorKind::Detp, DetpBoundary::Clip},
                                                                   {EstimatorKind::Detp, DetpBoundary::Linear}};
    for (int e = 0; e < 4; ++e) {
        const Figures f = measure(scene, cache, reference, estimators[e].first, estimators[e].second, radius);
        const Bound& b = c.bounds[e];
        std::printf("%s seed %llu, %s: all rms %.4f bias %+.4f | edge rms %.4f bias %+.4f | near rms %.4f bias %+.4f | "
                    "interior rms %.4f bias %+.4f | above panel bias %+.4f\n",
                    c.scene, static_cast<unsigned long long>(seed), b.estimator, f.report.all.relativeRms,
                    f.report.all.relativeBias, f.report.edge.relativeRms, f.report.edge.relativeBias,
                    f.report.nearEdge.relativeRms, f.report.nearEdge.relativeBias, f.report.interior.relativeRms,
                    f.report.interior.relativeBias, f.region.relativeBias);
        EXPECT_LE(f.report.all.relativeRms, b.allRms) << b.estimator;
        EXPECT_LE(std::fabs(f.report.edge.relativeBias), b.edgeBias) << b.estimator;
        // A bounded region must hold vertices: an empty one has a bias of 0, which passes any bound.
        if (b.nearBias > 0) {  // 0 on the corner scene, which has no vertex near an edge
            EXPECT_GT(f.report.nearEdge.vertices, 0u) << b.estimator << ": no vertex near an edge to bound";
            EXPECT_LE(std::fabs(f.report.nearEdge.relativeBias), b.nearBias) << b.estimator;
        }
        EXPECT_LE(f.report.interior.relativeRms, b.interiorRms) << b.estimator;
        if (b.regionBias > 0) {
            EXPECT_GT(f.region.vertices, 0u) << b.estimator << ": no ceiling vertex above the panel to bound";
            EXPECT_LE(std::fabs(f.region.relativeBias), b.regionBias) << b.estimator;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    Scenes, ReferenceAccuracy,
    ::testing::Values(Case{"data/cornell/cornell.gltf",
                           "cornell_f0000.ply",
                           {{"impact count", 0.073, 0.012, 0.019, 0.07, 0},
                            {"photon map", 0.17, 0.01, 0.023, 0.181, 0},
                            {"DETP clip", 0.045, 0.016, 0.024, 0.041, 0},
                            {"DETP linear", 0.049, 0.005, 0.01, 0.041, 0}}},
                      Case{"tests/scenes/ceiling_panel/ceiling_panel.gltf",
                           "ceiling_panel_f0000.ply",
                           {{"impact count", 0.065, 0.016, 0.218, 0.028, 5.06},
                            {"photon map", 0.215, 0.053, 0.943, 0.143, 5.14},
                            {"DETP clip", 0.038, 0.012, 0.061, 0.033, 5.14},
                            {"DETP linear", 0.042, 0.006, 0.098, 0.033, 5.14}}},
                      Case{"tests/scenes/corner_point_light.gltf",
                           "corner_point_light_f0000.ply",
                           {{"impact count", 0.028, 0.065, 0, 0.018, 0},
                            {"photon map", 0.093, 0.055, 0, 0.091, 0},
                            {"DETP clip", 0.028, 0.033, 0, 0.024, 0},
                            {"DETP linear", 0.031, 0.024, 0, 0.024, 0}}},
                      Case{"tests/scenes/open_box_sky.gltf",
                           "open_box_sky_f0000.ply",
                           {{"impact count", 0.0501, 0.0102, 0.212, 0.0371, 0},
                            {"photon map", 0.162, 0.0068, 0.11, 0.167, 0},
                            {"DETP clip", 0.071, 0.0083, 0.097, 0.0705, 0},
                            {"DETP linear", 0.0788, 0.0221, 0.097, 0.0705, 0}}}),
    [](const ::testing::TestParamInfo<Case>& info) { return caseName(info.param); });
