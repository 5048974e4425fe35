// Aimed emission (issue 12): projection maps send photons only toward what can count, each
// carrying the power of the part of the light actually sampled. It must change nothing in
// expectation (a far plate's irradiance, at its interior and its open edges, aimed and unaimed;
// a sliver thinner than a map cell gets its share), nothing at all where every direction reaches
// the scene, and nothing of the project's exactness (the same bytes for any thread count;
// incremental == full is checked with aimed lights in incremental_test.cpp).
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

#include "pipeline/frame_solver.h"
#include "test_support.h"
#include "trace/photon_tracer.h"

using namespace qsgi;

namespace {

constexpr float kIntensity = 10.0f;  // W/sr
const Vec3f kLight(0.0f, 5.0f, 0.0f);

// DETP (clip) irradiance of every vertex, traced as a render traces it (aimed at r beside the
// geometry) or unaimed.
struct Solved {
    std::vector<Vec3f> irradiance;
    uint64_t missing = 0;
    double emittedFraction = 0;
};
Solved solveDetp(const Scene& source, uint64_t photons, bool aim, float radius) {
    Scene scene = source;
    EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator.kind = EstimatorKind::Detp;
    s.estimator.radius = radius;
    s.trace = TraceSettings{photons, 3, 32, EmissionAim{aim, 0}, PhotonSampling{}};
    s.update.fullRecompute = true;
    FrameSolver solver(scene, device, s);
    Solved out;
    const FrameSolver::Solution solved = solver.solve(scene.restPose());
    out.irradiance = solved.radiosity.irradiance;
    out.missing = solved.record.photonsMissingScene;
    out.emittedFraction = solver.emittedFraction();
    return out;
}

// E at a point of a plane y = const facing up from the scene's first light (W/m²), in the
// scene's re-centred frame.
double analyticIrradiance(const Scene& scene, const Vec3f& p) {
    const Vec3d d = Vec3d(scene.lights[0].position - p);
    const double d2 = dot(d, d);
    return kIntensity * d.y / (d2 * std::sqrt(d2));
}

}  // namespace

// A plate 5 m under a point light covers 1/300 of its sphere of directions. Aimed and unaimed
// runs estimate the same irradiance, in the plate's interior and along its open edges, where DETP
// counts photons that pass beside the plate (the maps keep directions within r of its discs).
TEST(AimedEmission, FarPlateHasTheSameIrradianceAimedAndUnaimed) {
    const float radius = 0.05f;
    Scene plate = testscenes::plane(0.5f, 20, Vec3f(0.0f));
    testscenes::addPointLight(plate, kLight, Vec3f(kIntensity));
    const uint64_t aimedPhotons = 200000, unaimedPhotons = 4000000;
    const Solved aimed = solveDetp(plate, aimedPhotons, true, radius);
    const Solved unaimed = solveDetp(plate, unaimedPhotons, false, radius);

    // Photons reaching the plate: what the means' noise rests on.
    const double hitsAimed = double(aimedPhotons - aimed.missing), hitsUnaimed = double(unaimedPhotons - unaimed.missing);
    double interior[2] = {0, 0}, edge[2] = {0, 0};
    int interiorCount = 0, edgeCount = 0;
    for (uint32_t v = 0; v < plate.vertexCount(); ++v) {
        const Vec3f& p = plate.positions[v];
        const double E = analyticIrradiance(plate, p);
        const bool atEdge = std::max(std::abs(p.x), std::abs(p.z)) > 0.5f - 1e-4f;
        const bool inside = std::max(std::abs(p.x), std::abs(p.z)) < 0.5f - 1.5f * radius;
        if (!atEdge && !inside) continue;
        (atEdge ? edge : interior)[0] += aimed.irradiance[v].y / E;
        (atEdge ? edge : interior)[1] += unaimed.irradiance[v].y / E;
        ++(atEdge ? edgeCount : interiorCount);
    }
    for (double& m : interior) m /= interiorCount;
    for (double& m : edge) m /= edgeCount;
    // The mean over the vertices of E/E_true is (photons counted)/(photons expected) to first
    // order: its relative standard deviation is 1/√H for H photons over the region. Edge discs
    // see the photons of a band r wide along the perimeter: a share 4·(2·0.5)·r / 1 m² of H.
    // DETP clip at an open edge keeps E's whole disc reachable (nothing occludes it), so it too is
    // unbiased; 4.5 standard deviations leave a false failure at 1 in 10^5.
    const double edgeShare = 4 * 1.0 * radius / 1.0;
    const double sigmaInterior = std::sqrt(1 / hitsAimed + 1 / hitsUnaimed);
    const double sigmaEdge = std::sqrt(1 / (edgeShare * hitsAimed) + 1 / (edgeShare * hitsUnaimed));
    std::printf("far plate: %.1f %% of aimed photons miss (unaimed %.1f %%), emitted fraction %.5f; interior E/E_true "
                "aimed %.4f unaimed %.4f (σ of the difference %.4f); open edges %.4f vs %.4f (σ %.4f)\n",
                100.0 * aimed.missing / aimedPhotons, 100.0 * unaimed.missing / unaimedPhotons, aimed.emittedFraction,
                interior[0], interior[1], sigmaInterior, edge[0], edge[1], sigmaEdge);
    EXPECT_LT(std::abs(interior[0] - interior[1]), 4.5 * sigmaInterior);
    EXPECT_LT(std::abs(edge[0] - edge[1]), 4.5 * sigmaEdge);
    EXPECT_LT(std::abs(interior[0] - 1), 4.5 / std::sqrt(hitsAimed));
    // What the map keeps is the plate widened by the band where its edge discs (facing the light,
    // so seen whole) count photons: (1 + 2r/1 m)² = 1.21 times its area, so 1 − 1/1.21 = 17 % of
    // the aimed photons miss it by design, plus the cells along the outline. Unaimed, 99.7 % miss.
    EXPECT_LT(double(aimed.missing) / aimedPhotons, 0.25);
    EXPECT_LT(aimed.emittedFraction, 0.01);
}

// A sliver 1 mm wide, 2.5 m aside, is far thinner than a map cell (~2 cm there): a map made by
// probing with rays would likely drop it; the conservative map keeps it, and the power that
// lands on it equals I·Ω of its solid angle.
TEST(AimedEmission, ThinSliverFarFromTheRestReceivesItsShare) {
    const float width = 1e-3f, offset = 2.5f;
    Scene scene = testscenes::plateAndSliver(0.5f, 8, width, offset, Vec3f(0.0f));
    testscenes::addPointLight(scene, kLight, Vec3f(kIntensity));
    const uint64_t photons = 1000000;
    EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    const PhotonTracer tracer(scene, bvh, TraceSettings{photons, 5, 32, EmissionAim{true, 0}, PhotonSampling{}});
    const RayCache cache = tracer.traceAll();
    // The sliver's triangles follow the plate's (instances in order).
    const uint32_t firstSliverTriangle = scene.instances[1].firstTriangle;
    double landed = 0, expected = 0;
    uint64_t hits = 0;
    std::vector<Segment> path;
    for (size_t p = 0; p < cache.pathCount(); ++p) {
        path.clear();
        cache.appendPath(p, path);
        if (path.empty()) continue;
        const Segment& s = path.front();
        if (s.hasImpact() && s.triangle >= firstSliverTriangle) {
            landed += s.power.y;
            ++hits;
        }
    }
    for (uint32_t t = firstSliverTriangle; t < scene.triangleCount(); ++t) {
        // I·Ω of a small triangle: E at its centroid times its area (1 mm × 10 cm, at 5.6 m).
        const Triangle& tri = scene.triangles[t];
        const Vec3f c = (scene.positions[tri.v[0]] + scene.positions[tri.v[1]] + scene.positions[tri.v[2]]) * (1.0f / 3);
        expected += analyticIrradiance(scene, c) * scene.triangleArea(t);
    }
    // Each hit carries the same power, and hits are binomial: σ = power·√hits.
    const double photonPower = tracer.lights().totalPower().y / double(photons);
    std::printf("sliver: %llu hits, power %.4g W, expected %.4g W (σ %.2g)\n", static_cast<unsigned long long>(hits), landed,
                expected, photonPower * std::sqrt(double(hits)));
    ASSERT_GT(hits, 100u);
    EXPECT_LT(std::abs(landed - expected), 4.5 * photonPower * std::sqrt(double(hits)) + 1e-3 * expected);
}

// A light inside a closed box reaches geometry in every direction: the map keeps every cell, and
// emission is exactly the unaimed one.
TEST(AimedEmission, LightInsideAClosedBoxChangesNothing) {
    Scene box = testscenes::closedBox(6);
    testscenes::addPointLight(box, Vec3f(0.1f, 0.6f, -0.2f), Vec3f(5.0f));
    EXPECT_TRUE(sameSegments(traceScene(box, 20000, 9, true), traceScene(box, 20000, 9, false)));
    EmbreeDevice device;
    const SceneBvh bvh(device, box);
    EXPECT_EQ(LightSampler(box, 1000, bvh.rayEpsilon(), EmissionAim{true, 0.05f}).emittedFraction(), 1.0);
}

// Maps are refined in parallel; the photons they send must not depend on the threads.
TEST(AimedEmission, SameBytesForAnyThreadCount) {
    Scene scene = testscenes::plateAndSliver(0.5f, 8, 1e-3f, 2.5f, Vec3f(0.5f));
    testscenes::addPointLight(scene, kLight, Vec3f(kIntensity));
    PunctualLight sun;
    sun.type = LightType::Directional;
    sun.direction = normalize(Vec3f(0.2f, -1.0f, 0.1f));
    sun.intensity = Vec3f(2.0f);
    scene.lights.push_back(sun);
    RayCache one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = traceScene(scene, 30000, 4);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = traceScene(scene, 30000, 4);
    }
    EXPECT_TRUE(sameSegments(one, two));
}
