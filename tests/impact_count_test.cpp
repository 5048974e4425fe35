// Impact count against analytic answers (docs/design.md §5), with tolerances derived from the Poisson
// statistics of the hit counts rather than picked to pass.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "estimate/impact_count.h"
#include "test_support.h"
#include "trace/photon_tracer.h"

#include <tbb/global_control.h>

using namespace qsgi;

namespace {

struct Estimate {
    RayCache cache;
    VertexRadiosity result;
    std::vector<PowerSum> triangleSums;
    double quantum = 0;
};

Estimate runImpactCount(const Scene& scene, uint64_t photons, uint64_t seed = 7, const PhotonSampling& sampling = {}) {
    EmbreeDevice device;
    SceneBvh bvh(device, scene);
    PhotonTracer tracer(scene, bvh, TraceSettings{photons, seed, 32, EmissionAim{}, sampling});
    Estimate e;
    e.cache = tracer.traceAll();
    ImpactCount ic(scene);
    ic.accumulate(e.cache);
    const PowerQuantizer q(e.cache.maxPhotonPower);
    e.result = ic.estimate(scene, q);
    e.triangleSums = ic.triangleSums();
    e.quantum = q.quantum();
    return e;
}

}  // namespace

// Closed sphere, radius 1, ρ = 0.5, a 1 W/sr point light at the centre. Direct irradiance is
// I/r² = 1 W/m²; every bounce spreads the reflected power uniformly over a sphere, so
// E = E_direct / (1 − ρ) = 2 W/m² everywhere.
TEST(ImpactCount, ClosedSphereGivesTwoWattsPerSquareMetre) {
    const Scene scene = testscenes::closedSphere(1.0f, 5, Vec3f(0.5f));
    ASSERT_GE(scene.vertexCount(), 5000u);
    Scene lit = scene;
    testscenes::addPointLight(lit, Vec3f(0.0f), Vec3f(1.0f));
    const uint64_t photons = 1000000;
    for (const SamplerKind sampler : {SamplerKind::Random, SamplerKind::Sobol}) {
        SCOPED_TRACE(samplerName(sampler));
        const Estimate e = runImpactCount(lit, photons, 7, PhotonSampling{sampler, 2});

        // The mesh is an inscribed polyhedron of area A < 4π. Conservation then fixes the
        // area-weighted mean: Σ E_τ A_τ (1−ρ) = 4π I, so <E> = 4π I / (A (1−ρ)).
        double area = 0;
        for (uint32_t t = 0; t < lit.triangleCount(); ++t) area += lit.triangleArea(t);
        const double expectedMean = 4 * M_PI / (area * 0.5);
        EXPECT_NEAR(expectedMean, 2.0, 0.02) << "the tessellation is too coarse to stand in for a sphere";

        double sum = 0;
        for (const Vec3f& E : e.result.irradiance) sum += E.y;
        const double mean = sum / double(lit.vertexCount());
        EXPECT_NEAR(mean, 2.0, 0.02);  // the 1 %
        EXPECT_NEAR(mean, expectedMean, 0.01 * expectedMean);

        // Spread. With ρ = 0.5 and survival p = max ρ = 0.5 every impact carries the photon's own
        // power Φ0 = 4π/N, so a triangle's hit count is (very nearly) Poisson with mean
        // λ_τ = E A_τ / Φ0, and Var(E_τ) = E Φ0 / A_τ. A vertex averages its k triangles:
        // Var(E_v) = Σ_τ Var(E_τ) / k². The observed variance over vertices must match the mean
        // predicted variance; the sample variance of ~10^4 vertices (correlated in groups of about 6
        // through shared triangles, so ~1700 independent ones) has a relative standard error of
        // sqrt(2/1700) ≈ 3.4 %; 15 % is over four standard errors. That is for independent photons
        // (the random sampler); Sobol photons stratify the directions from the light, so their
        // spread must be well below Poisson's (measured: 0.51 of it).
        const double phi0 = e.cache.maxPhotonPower;  // 4π I/N, or the aimed solid angle's I Ω/N
        std::vector<double> predictedVar(lit.vertexCount(), 0.0);
        std::vector<int> k(lit.vertexCount(), 0);
        for (uint32_t t = 0; t < lit.triangleCount(); ++t)
            for (uint32_t v : lit.triangles[t].v) {
                predictedVar[v] += expectedMean * phi0 / lit.triangleArea(t);
                ++k[v];
            }
        double predicted = 0, observed = 0;
        for (size_t v = 0; v < lit.vertexCount(); ++v) {
            predicted += predictedVar[v] / (double(k[v]) * k[v]);
            const double d = e.result.irradiance[v].y - mean;
            observed += d * d;
        }
        predicted /= double(lit.vertexCount());
        observed /= double(lit.vertexCount() - 1);
        std::printf("sphere, %s: mean E %.5f (expected %.5f), variance observed/predicted %.3f\n", samplerName(sampler), mean,
                    expectedMean, observed / predicted);
        if (sampler == SamplerKind::Random) {
            EXPECT_NEAR(observed / predicted, 1.0, 0.15) << "observed variance " << observed << ", Poisson predicts " << predicted;
        } else {
            EXPECT_LT(observed / predicted, 0.7) << "observed variance " << observed << ", Poisson predicts " << predicted;
        }

        // Radiosity B = ρE (no emission).
        for (size_t v = 0; v < lit.vertexCount(); v += 97)
            EXPECT_FLOAT_EQ(e.result.radiosity[v].x, 0.5f * e.result.irradiance[v].x);
    }
}

// A plane with albedo 0 under a point light of I = 1 W/sr at height h = 1: E = I cosθ / d² =
// I h / d³. The mean over a ring of vertices is a fixed weighted sum of triangle estimates, so its
// variance follows from the triangles' Poisson counts exactly; the test allows 4 σ.
TEST(ImpactCount, PlaneUnderPointLightFollowsInverseSquareCosineLaw) {
    Scene scene = testscenes::plane(1.6f, 128, Vec3f(0.0f));
    const float h = 1.0f;
    testscenes::addPointLight(scene, Vec3f(0, h, 0), Vec3f(1.0f));
    const uint64_t photons = 1000000;
    const Estimate e = runImpactCount(scene, photons);
    const double phi0 = e.cache.maxPhotonPower;  // I Ω/N: the solid angle aimed at the plane

    std::vector<int> k(scene.vertexCount(), 0);
    for (const Triangle& t : scene.triangles)
        for (uint32_t v : t.v) ++k[v];
    auto world = [&](const Vec3f& p) { return Vec3d(p) + scene.worldOrigin; };
    auto analytic = [&](const Vec3d& p) {
        const double d2 = p.x * p.x + p.z * p.z + h * h;
        return h / (d2 * std::sqrt(d2));
    };
    for (auto [r0, r1] : {std::pair{0.0, 0.3}, std::pair{0.8, 1.0}, std::pair{1.2, 1.4}}) {
        std::vector<size_t> ring;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = world(scene.positions[v]);
            const double r = std::hypot(p.x, p.z);
            if (r >= r0 && r < r1 && k[v] == 6) ring.push_back(v);  // interior vertices only
        }
        ASSERT_GT(ring.size(), 100u);
        // ring mean = Σ_τ w_τ E_τ; expectation uses E at the triangle centroids (the triangle
        // average to second order), variance Σ w_τ² E_τ Φ0 / A_τ.
        std::vector<double> w(scene.triangleCount(), 0.0);
        std::vector<std::vector<uint32_t>> trisOf(scene.vertexCount());
        for (uint32_t t = 0; t < scene.triangleCount(); ++t)
            for (uint32_t v : scene.triangles[t].v) trisOf[v].push_back(t);
        double measured = 0;
        for (size_t v : ring) {
            measured += e.result.irradiance[v].y;
            for (uint32_t t : trisOf[v]) w[t] += 1.0 / (double(ring.size()) * k[v]);
        }
        measured /= double(ring.size());
        double expected = 0, variance = 0;
        for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
            if (w[t] == 0) continue;
            const Triangle& tri = scene.triangles[t];
            const Vec3d c = (world(scene.positions[tri.v[0]]) + world(scene.positions[tri.v[1]]) + world(scene.positions[tri.v[2]])) / 3.0;
            const double Et = analytic(c);
            expected += w[t] * Et;
            variance += w[t] * w[t] * Et * phi0 / scene.triangleArea(t);
        }
        EXPECT_NEAR(measured, expected, 4 * std::sqrt(variance)) << "ring " << r0 << ".." << r1;
    }
}

// In a closed box every photon's power is eventually absorbed:
// Σ_τ E_τ A_τ (1 − ρ_τ) = emitted power. The absorbed total is a sum over independent paths, each
// absorbing Φ0 on average; its relative noise at 3·10^5 photons is ~0.2 %, so the 1 % asked for
// is about five standard errors.
TEST(ImpactCount, ClosedBoxAbsorbsTheEmittedPower) {
    Scene scene = testscenes::closedBox(24);
    testscenes::addPointLight(scene, Vec3f(0.2f, 0.5f, -0.1f), Vec3f(2.0f, 1.5f, 1.0f));
    const Estimate e = runImpactCount(scene, 300000);
    Vec3d absorbed(0.0);
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Vec3d E = e.triangleSums[t].watts(PowerQuantizer(e.cache.maxPhotonPower)) / double(scene.triangleArea(t));
        const Vec3d albedo(scene.materials[scene.triangleMaterial[t]].albedo);
        absorbed += E * (Vec3d(1.0) - albedo) * double(scene.triangleArea(t));
    }
    const Vec3d emitted = Vec3d(2.0, 1.5, 1.0) * (4 * M_PI);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(absorbed[c] / emitted[c], 1.0, 0.01) << "channel " << c;
}

// A translated and scaled copy of a scene traces the same photons (docs/design.md §4: epsilons scale with
// the scene and positions are re-centred).
TEST(ImpactCount, TranslatedSceneGivesTheSameAnswer) {
    Scene a = testscenes::closedBox(8);
    testscenes::addPointLight(a, Vec3f(0.2f, 0.5f, -0.1f), Vec3f(1.0f));
    Scene b = a;
    b.worldOrigin = b.worldOrigin + Vec3d(1e5, -3e4, 2e5);  // the same scene far from the origin
    const Estimate ea = runImpactCount(a, 20000), eb = runImpactCount(b, 20000);
    ASSERT_EQ(ea.result.irradiance.size(), eb.result.irradiance.size());
    for (size_t v = 0; v < ea.result.irradiance.size(); ++v) ASSERT_EQ(ea.result.irradiance[v], eb.result.irradiance[v]);
}

TEST(ImpactCount, ResultsAreIdenticalForAnyThreadCount) {
    Scene scene = testscenes::closedBox(16);
    testscenes::addPointLight(scene, Vec3f(0.0f), Vec3f(1.0f));
    Estimate one, many;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = runImpactCount(scene, 50000);
    }
    many = runImpactCount(scene, 50000);
    ASSERT_TRUE(sameSegments(one.cache, many.cache));
    for (size_t v = 0; v < scene.vertexCount(); ++v) ASSERT_EQ(one.result.radiosity[v], many.result.radiosity[v]);
}
