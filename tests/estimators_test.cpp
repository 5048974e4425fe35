// Photon map and DETP (docs/design.md §5): indexes equal brute force, analytic answers, the border claim
// of the paper, geometry independence, and extreme parameters.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <vector>

#include "estimate/detp.h"
#include "estimate/estimator.h"
#include "estimate/morton_order.h"
#include "estimate/photon_map.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "trace/photon_tracer.h"

using namespace qsgi;

namespace {

RayCache trace(const Scene& scene, uint64_t photons, uint64_t seed = 11) { return traceScene(scene, photons, seed); }

std::vector<Vec3f> estimate(const Scene& scene, const RayCache& cache, EstimatorKind kind, float radius, int k = 50,
                            bool useIndex = true, bool sortQueries = true, DetpIndex detpIndex = DetpIndex::Embree,
                            DetpBoundary boundary = DetpBoundary::Clip) {
    EstimatorSettings s;
    s.kind = kind;
    s.radius = radius;
    s.photonMap.k = k;
    s.useIndex = useIndex;
    s.sortQueries = sortQueries;
    s.detp.index = detpIndex;
    s.detp.boundary = boundary;
    return estimateWith(scene, cache, s).irradiance;
}

float largestComponent(const std::vector<Vec3f>& values) {
    float m = 0;
    for (const Vec3f& v : values) m = std::max(m, maxComponent(v));
    return m;
}

void expectEqualToRounding(const std::vector<Vec3f>& indexed, const std::vector<Vec3f>& reference, const std::string& what) {
    ASSERT_EQ(indexed.size(), reference.size());
    const double tolerance = 1e-9 * largestComponent(reference);
    size_t mismatches = 0;
    for (size_t v = 0; v < reference.size(); ++v)
        for (int c = 0; c < 3; ++c)
            if (std::fabs(double(indexed[v][c]) - double(reference[v][c])) > tolerance) ++mismatches;
    EXPECT_EQ(mismatches, 0u) << what << ": " << mismatches << " values differ by more than " << tolerance;
}

// Area of the intersection of two discs of radius r whose centres are `d` apart.
double discOverlap(double d, double r) {
    if (d >= 2 * r) return 0;
    return 2 * r * r * std::acos(d / (2 * r)) - 0.5 * d * std::sqrt(4 * r * r - d * d);
}

Scene litCornell() {
    Warnings w;
    return loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
}

Scene litBoxOnFloor() {
    Scene s = testscenes::boxOnFloor(48, 12, Vec3f(0.5f));
    testscenes::addPointLight(s, Vec3f(0.8f, 1.5f, 0.6f), Vec3f(3.0f));
    return s;
}

}  // namespace

// Radii from below the vertex spacing to beyond the whole scene. Every boundary rule, indexed
// (sorted and unsorted) == brute force. The Cornell walls are 2 m and its vertices 3.1 cm apart;
// the box-on-floor scene (a 4 m floor, 8.3 cm apart) also takes the discs wider than the scene
// (its diagonal is 5.7 m): there every disc meets every segment, and brute force and the disc
// regions cost vertices × segments and vertices × triangles, so that is done on the coarser
// scene with fewer photons. On Cornell (21,636 vertices) brute force costs vertices × segments at
// every radius: 1500 photons there (about 3,100 segments, some 6.7·10⁷ pairs each brute-force
// pass weighs), where 3000 took twice the time for a property — two searches summing the same
// pairs — that holds at any photon count.
TEST(Estimators, IndexedPhotonMapAndDetpEqualBruteForce) {
    using Radii = std::vector<std::pair<float, int>>;  // radius, photons
    // Under sanitizers (kSanitized: ten times slower) one radius on Cornell and three on the box,
    // still below the spacing, between and beyond the scene.
    const Radii fine = kSanitized ? Radii{{0.05f, 1500}} : Radii{{0.01f, 1500}, {0.05f, 1500}, {0.3f, 1500}};
    const Radii wide = kSanitized ? Radii{{0.01f, 3000}, {0.3f, 3000}, {6.0f, 500}}
                                  : Radii{{0.01f, 3000}, {0.05f, 3000}, {0.3f, 3000}, {3.0f, 500}, {6.0f, 500}};
    for (const auto& [name, scene, radii] : {std::tuple{std::string("cornell"), litCornell(), fine},
                                             std::tuple{std::string("box on floor"), litBoxOnFloor(), wide}}) {
        EmbreeDevice device;
        const SceneBvh bvh(device, scene);
        for (auto [radius, photons] : radii) {
            const RayCache cache = trace(scene, uint64_t(photons));
            ASSERT_GT(cache.segmentCount(), uint64_t(photons));
            // Regions once per radius: the estimates below differ only in how they search.
            DiscRegions discs(radius, false), covered(radius, true);
            discs.computeAll(scene, bvh);
            covered.computeAll(scene, bvh);
            auto run = [&](EstimatorKind kind, DetpBoundary rule, bool useIndex, bool sortQueries,
                           DetpIndex index = DetpIndex::Embree) {
                EstimatorSettings s;
                s.kind = kind;
                s.detp.boundary = rule;
                s.radius = radius;
                s.photonMap.k = 20;
                s.useIndex = useIndex;
                s.sortQueries = sortQueries;
                s.detp.index = index;
                return estimateVertexRadiosity(scene, bvh, cache, s, device,
                                               kind == EstimatorKind::PhotonMap ? &covered : &discs).irradiance;
            };
            for (DetpBoundary rule : {DetpBoundary::Clip, DetpBoundary::Linear, DetpBoundary::Paper}) {
                const std::string what = name + ", r = " + std::to_string(radius) + ", " + detpBoundaryName(rule);
                const auto detpBrute = run(EstimatorKind::Detp, rule, false, true);
                expectEqualToRounding(run(EstimatorKind::Detp, rule, true, true), detpBrute, "DETP " + what);
                expectEqualToRounding(run(EstimatorKind::Detp, rule, true, false), detpBrute, "DETP unsorted " + what);
                EXPECT_GT(largestComponent(detpBrute), 0.0f) << what;
                if (rule != DetpBoundary::Linear) {
                    const auto pmBrute = run(EstimatorKind::PhotonMap, rule, false, true);
                    expectEqualToRounding(run(EstimatorKind::PhotonMap, rule, true, true), pmBrute, "photon map " + what);
                    expectEqualToRounding(run(EstimatorKind::PhotonMap, rule, true, false), pmBrute,
                                          "photon map unsorted " + what);
                    // The FLANN candidate search sees a subset of the segments the exact rule
                    // counts (sums of positive powers over the same area).
                    const auto flann = run(EstimatorKind::Detp, rule, true, true, DetpIndex::Flann);
                    for (size_t v = 0; v < flann.size(); ++v)
                        for (int c = 0; c < 3; ++c) ASSERT_LE(flann[v][c], detpBrute[v][c]) << what << " vertex " << v;
                }
            }
        }
    }
}

// timing.json's detp_crossings: the crossings the indexed solve counted are the (segment, vertex)
// pairs the definition accepts, counted pair by pair (detpCounts on every pair).
TEST(Estimators, DetpCountsEveryCrossingTheDefinitionAccepts) {
    const Scene scene = litBoxOnFloor();
    EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    const RayCache cache = trace(scene, 2000);
    const std::vector<Segment> segments = cache.decodeAll();
    for (DetpBoundary rule : {DetpBoundary::Clip, DetpBoundary::Paper}) {
        SCOPED_TRACE(detpBoundaryName(rule));
        EstimatorSettings s;
        s.kind = EstimatorKind::Detp;
        s.detp.boundary = rule;
        s.radius = 0.3f;
        DiscRegions discs(s.radius, false);
        discs.computeAll(scene, bvh);
        const DiscRegions* regions = rule == DetpBoundary::Paper ? nullptr : &discs;
        VertexRadiosity out;
        const EstimateReport stats = Estimator::create(s, EstimatorContext{scene, bvh, device, regions})->solve(cache, out);
        uint64_t pairs = 0;
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            const VertexDisc disc = regions ? (*regions)[v] : VertexDisc{};
            DiscCrossing at;
            for (const Segment& seg : segments)
                pairs += detpCounts(seg, scene.positions[v], scene.normals[v], disc, s.radius, rule, &bvh, at);
        }
        EXPECT_EQ(stats.detpCrossings, pairs);
        EXPECT_GT(pairs, segments.size());
    }
}

// Inside of a closed sphere, ρ = 0.5, I = 1 W/sr at the centre: E = 2 W/m² (see ImpactCount's
// test). Each estimator's vertex mean is a mean over ~10^4 overlapping estimates of ≥ 50 impacts;
// its statistical error is well under 0.3 %, so the 1 % bounds the estimators' own bias
// (DETP's band ε⁺ is the sagitta here; the photon map's impacts lie on the curved surface).
TEST(Estimators, ClosedSphereGivesTwoWattsPerSquareMetreForEveryEstimator) {
    Scene scene = testscenes::closedSphere(1.0f, 5, Vec3f(0.5f));
    testscenes::addPointLight(scene, Vec3f(0.0f), Vec3f(1.0f));
    const RayCache cache = trace(scene, 1000000);
    for (auto [kind, radius] : {std::pair{EstimatorKind::ImpactCount, 0.0f}, std::pair{EstimatorKind::PhotonMap, 0.2f},
                                std::pair{EstimatorKind::Detp, 0.05f}}) {
        const auto E = estimate(scene, cache, kind, radius);
        double sum = 0;
        for (const Vec3f& e : E) sum += e.y;
        const double mean = sum / double(E.size());
        std::printf("sphere, %s: mean E = %.4f W/m^2\n", estimatorName(kind), mean);
        EXPECT_NEAR(mean, 2.0, 0.02) << estimatorName(kind);
    }
}

// A black plane (no interreflection) under I = 1 W/sr at h = 1 m: E = I h / d³. DETP's expectation
// at a vertex is exactly the mean of E over its disc (computed here by quadrature). Hits are
// Poisson, so Cov(E_v, E_w) = Φ0 E A_overlap(v, w) / (π r²)², which gives the variance of a ring
// mean; the test allows 4 σ. The photon map is checked the same way with the disc radius its k
// neighbours span (r_k² = (k−1) Φ0 / (π E)), 5 σ for that approximation.
TEST(Estimators, PlaneUnderPointLightMatchesTheInverseSquareCosineLaw) {
    Scene scene = testscenes::plane(1.6f, 128, Vec3f(0.0f));
    const double h = 1.0;
    testscenes::addPointLight(scene, Vec3f(0, float(h), 0), Vec3f(1.0f));
    const uint64_t photons = 1000000;
    const RayCache cache = trace(scene, photons);
    const double phi0 = cache.maxPhotonPower;  // I Ω/N: the solid angle aimed at the plane
    auto analytic = [&](double x, double z) {
        const double d2 = x * x + z * z + h * h;
        return h / (d2 * std::sqrt(d2));
    };
    const double r = 0.05;
    auto discAverage = [&](double x, double z) {
        double sum = 0;
        const int rings = 12, sectors = 24;
        for (int i = 0; i < rings; ++i)
            for (int j = 0; j < sectors; ++j) {
                const double rho = r * std::sqrt((i + 0.5) / rings), phi = 2 * M_PI * (j + 0.5) / sectors;
                sum += analytic(x + rho * std::cos(phi), z + rho * std::sin(phi));
            }
        return sum / (rings * sectors);
    };
    const auto detp = estimate(scene, cache, EstimatorKind::Detp, float(r));
    const auto pm = estimate(scene, cache, EstimatorKind::PhotonMap, 0.5f, 50);
    for (auto [r0, r1] : {std::pair{0.0, 0.3}, std::pair{0.8, 1.0}, std::pair{1.2, 1.4}}) {
        std::vector<size_t> ring;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3f& p = scene.positions[v];
            const double rr = std::hypot(p.x, p.z);
            if (rr >= r0 && rr < r1) ring.push_back(v);
        }
        const double n = double(ring.size());
        double detpMean = 0, detpExpected = 0, pmMean = 0, pmExpected = 0, detpVar = 0, pmVar = 0;
        for (size_t v : ring) {
            const Vec3f& p = scene.positions[v];
            detpMean += detp[v].y / n;
            detpExpected += discAverage(p.x, p.z) / n;
            pmMean += pm[v].y / n;
            pmExpected += analytic(p.x, p.z) / n;
        }
        for (size_t a : ring)
            for (size_t b : ring) {
                const Vec3f& pa = scene.positions[a];
                const Vec3f& pb = scene.positions[b];
                const double d = std::hypot(pa.x - pb.x, pa.z - pb.z);
                const double E = analytic(pa.x, pa.z);
                const double rk = std::sqrt(49 * phi0 / (M_PI * E));
                if (d < 2 * r) detpVar += phi0 * E * discOverlap(d, r) / std::pow(M_PI * r * r, 2) / (n * n);
                // Photon map: Var(E_v) = E²/(k−2) for the (k−1)/πr_k² estimator, spread by overlap.
                if (d < 2 * rk) pmVar += E * E / 48 * discOverlap(d, rk) / (M_PI * rk * rk) / (n * n);
            }
        std::printf("plane ring %.1f-%.1f m: DETP %.5f (expected %.5f ± %.5f), photon map %.5f (expected %.5f ± %.5f)\n",
                    r0, r1, detpMean, detpExpected, std::sqrt(detpVar), pmMean, pmExpected, std::sqrt(pmVar));
        EXPECT_NEAR(detpMean, detpExpected, 4 * std::sqrt(detpVar));
        EXPECT_NEAR(pmMean, pmExpected, 5 * std::sqrt(pmVar));
    }
}

// The published rule (`--detp-boundary paper`, kept for ablations; the default rules are tested
// in detp_boundary_test.cpp). The paper's claim: photon maps have problems at borders, DETP does not. An inside corner (floor
// and wall, black so only direct light counts) under a point light, at three placements declared
// before measuring: high above the corner, at 45°, and low.
//
// What the test asserts is DETP's exact expectation near the edge, by quadrature over each disc:
// a point p of the disc receives I cosθ/d² from the light if the light reaches p, or if the
// light's ray is stopped by the other surface at h with |p − h| ≤ r (the rule's extension of the
// segment by r past its impact). The vertex means must match within 5 σ (Poisson, with the
// covariance of overlapping discs). It then prints the mean relative bias of DETP and of the
// photon map against the true irradiance within one radius of the edge. The criterion
// (|DETP bias| ≤ ½ |photon-map bias|) is reported, not asserted: it holds only where one surface
// is lit much more steeply than the other (see the closing note of issue 4 for the numbers).
TEST(Estimators, PaperRuleMatchesItsExactExpectationAtAnInsideCorner) {
    const float r = 0.1f;
    // The corner is 0.5 m deep (floor and wall), not 2 m: the band measured lies within r of the
    // edge, and nothing beyond 2r of it reaches its discs (black surfaces, a point light; the
    // exact expectation below never looks further), so the other 1.5 m only cost photons and
    // vertices. The photons are those of the 2 m corner (10⁶, aimed: about half of them land, as
    // many as 2·10⁶ unaimed) times the share of its aimed solid angle that the 0.5 m corner keeps
    // (0.175, 0.301, 0.176 for the three lights), rounded up: as many photons per steradian, so
    // φ0 and the variance below are those of the 2 m corner, or smaller.
    for (const auto& [light, photons] : {std::pair{Vec3d(0.0, 1.5, 0.5), uint64_t(180000)},
                                         std::pair{Vec3d(0.0, 1.0, 1.0), uint64_t(305000)},
                                         std::pair{Vec3d(0.0, 0.5, 1.5), uint64_t(180000)}}) {
        Scene scene = testscenes::corner(128, Vec3f(0.0f), 0.5f);
        testscenes::addPointLight(scene, Vec3f(light), Vec3f(1.0f));
        const RayCache cache = trace(scene, photons);
        std::printf("inside corner, light (%.1f, %.1f, %.1f): %llu photons, φ0 %.4g\n", light.x, light.y, light.z,
                    static_cast<unsigned long long>(photons), double(cache.maxPhotonPower));
        const double phi0 = cache.maxPhotonPower;  // I Ω/N: the solid angle aimed at the corner
        const auto detp = estimate(scene, cache, EstimatorKind::Detp, r, 50, true, true, DetpIndex::Embree, DetpBoundary::Paper);
        const auto pm = estimate(scene, cache, EstimatorKind::PhotonMap, r, 50, true, true, DetpIndex::Embree, DetpBoundary::Paper);

        // Expected DETP at vertex p (side 0: floor y = 0, normal +y; side 1: wall z = 0, normal +z).
        auto expectedDetp = [&](const Vec3d& v, int side) {
            const int rings = 24, sectors = 48;
            double sum = 0;
            for (int i = 0; i < rings; ++i)
                for (int j = 0; j < sectors; ++j) {
                    const double rho = r * std::sqrt((i + 0.5) / rings), phi = 2 * M_PI * (j + 0.5) / sectors;
                    const double a = rho * std::cos(phi), b = rho * std::sin(phi);
                    const Vec3d p = side == 0 ? Vec3d(v.x + a, 0, v.z + b) : Vec3d(v.x + a, v.y + b, 0);
                    const Vec3d toLight = light - p;
                    const double d = length(toLight);
                    const double density = (side == 0 ? toLight.y : toLight.z) / (d * d * d);
                    const double behind = side == 0 ? p.z : p.y;  // < 0: behind the other surface
                    if (behind >= 0) {
                        sum += density;
                        continue;
                    }
                    // Where the light's ray towards p meets the other surface's plane.
                    const double s = side == 0 ? light.z / (light.z - p.z) : light.y / (light.y - p.y);
                    const Vec3d h = light + (p - light) * s;
                    if (length(p - h) <= r) sum += density;
                }
            return sum / (rings * sectors);
        };

        std::vector<size_t> band;
        std::vector<int> sideOf;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = Vec3d(scene.positions[v]) + scene.worldOrigin;
            const int side = scene.normals[v].y > 0.5f ? 0 : 1;
            if ((side == 0 ? p.z : p.y) > r || std::fabs(p.x) > 0.5) continue;
            band.push_back(v);
            sideOf.push_back(side);
        }
        const double n = double(band.size());
        double measured = 0, expected = 0, variance = 0, detpBias = 0, pmBias = 0;
        std::vector<double> truth(band.size());
        for (size_t i = 0; i < band.size(); ++i) {
            const Vec3d p = Vec3d(scene.positions[band[i]]) + scene.worldOrigin;
            const Vec3d toLight = light - p;
            const double d = length(toLight);
            truth[i] = (sideOf[i] == 0 ? toLight.y : toLight.z) / (d * d * d);
            measured += detp[band[i]].y / n;
            expected += expectedDetp(p, sideOf[i]) / n;
            detpBias += (detp[band[i]].y - truth[i]) / truth[i] / n;
            pmBias += (pm[band[i]].y - truth[i]) / truth[i] / n;
        }
        for (size_t i = 0; i < band.size(); ++i)
            for (size_t j = 0; j < band.size(); ++j) {
                const double d = length(Vec3d(scene.positions[band[i]]) - Vec3d(scene.positions[band[j]]));
                if (d >= 2 * r) continue;
                // Discs on different surfaces share only the photons near the edge: half the
                // same-plane overlap is a generous bound for them.
                const double overlap = discOverlap(d, r) * (sideOf[i] == sideOf[j] ? 1.0 : 0.5);
                variance += phi0 * std::sqrt(truth[i] * truth[j]) * overlap / std::pow(M_PI * r * r, 2) / (n * n);
            }
        std::printf("inside corner, light (%.1f, %.1f, %.1f), r = %.2f, %zu vertices within r of the edge: DETP mean %.5f, "
                    "exact expectation %.5f ± %.5f; mean relative bias against the true irradiance: DETP %+.4f, photon "
                    "map %+.4f; |DETP| <= |photon map|/2: %s\n",
                    light.x, light.y, light.z, r, band.size(), measured, expected, std::sqrt(variance), detpBias, pmBias,
                    std::fabs(detpBias) <= 0.5 * std::fabs(pmBias) ? "yes" : "no");
        EXPECT_NEAR(measured, expected, 5 * std::sqrt(variance));
    }
}

// The same plane tessellated coarsely and finely: DETP and the photon map give the same answers
// at the shared vertices (they do not depend on triangles), impact count's noise grows as the
// triangles shrink (its variance goes as 1/area).
TEST(Estimators, DetpAndPhotonMapAreIndependentOfTessellation) {
    Scene coarse = testscenes::plane(1.0f, 16, Vec3f(0.0f)), fine = testscenes::plane(1.0f, 128, Vec3f(0.0f));
    testscenes::addPointLight(coarse, Vec3f(0, 1, 0), Vec3f(1.0f));
    testscenes::addPointLight(fine, Vec3f(0, 1, 0), Vec3f(1.0f));
    const uint64_t photons = 400000;
    // Unaimed: a projection map follows the tessellation's discs, so aimed photons would not fly
    // the same paths over both meshes, and this compares the estimators, not the emission.
    const RayCache cc = traceScene(coarse, photons, 11, false), cf = traceScene(fine, photons, 11, false);
    // Shared interior vertices: coarse (i, j) is fine (8i, 8j).
    auto fineIndex = [](int i, int j) { return size_t(8 * j) * 129 + size_t(8 * i); };
    double detpDiff = 0, pmDiff = 0, icCoarseVar = 0, icFineVar = 0;
    const auto detpC = estimate(coarse, cc, EstimatorKind::Detp, 0.1f), detpF = estimate(fine, cf, EstimatorKind::Detp, 0.1f);
    const auto pmC = estimate(coarse, cc, EstimatorKind::PhotonMap, 0.5f), pmF = estimate(fine, cf, EstimatorKind::PhotonMap, 0.5f);
    const auto icC = estimate(coarse, cc, EstimatorKind::ImpactCount, 0), icF = estimate(fine, cf, EstimatorKind::ImpactCount, 0);
    int n = 0;
    for (int j = 2; j <= 14; ++j)
        for (int i = 2; i <= 14; ++i) {
            const size_t vc = size_t(j) * 17 + size_t(i), vf = fineIndex(i, j);
            ASSERT_EQ(coarse.positions[vc], fine.positions[vf]);
            const Vec3f& p = coarse.positions[vc];
            const double d2 = p.x * p.x + p.z * p.z + 1.0, E = 1.0 / (d2 * std::sqrt(d2));
            detpDiff = std::max(detpDiff, std::fabs(double(detpC[vc].y) - detpF[vf].y) / E);
            pmDiff = std::max(pmDiff, std::fabs(double(pmC[vc].y) - pmF[vf].y) / E);
            icCoarseVar += std::pow(icC[vc].y / E - 1, 2);
            icFineVar += std::pow(icF[vf].y / E - 1, 2);
            ++n;
        }
    std::printf("tessellation 16 vs 128 cells: max relative difference DETP %.2g, photon map %.2g; "
                "impact-count relative variance %.4f vs %.4f (ratio %.1f)\n",
                detpDiff, pmDiff, icCoarseVar / n, icFineVar / n, icFineVar / icCoarseVar);
    // The photons fly the same paths over both meshes (the plane is the same surface), so any
    // difference is float rounding of the impact points, far below the noise (~10 %).
    EXPECT_LT(detpDiff, 1e-3);
    EXPECT_LT(pmDiff, 1e-3);
    // Triangle area shrinks 64x; even after each vertex averages its triangles, the variance must
    // grow by far more than noise in the variance estimates (~20 %) could explain.
    EXPECT_GT(icFineVar / icCoarseVar, 10.0);
}

TEST(Estimators, ExtremeParametersStayFinite) {
    Scene scene = litBoxOnFloor();
    const RayCache cache = trace(scene, 2000);
    auto allFinite = [](const std::vector<Vec3f>& E) {
        for (const Vec3f& e : E)
            if (!isFinite(e) || e.x < 0) return false;
        return true;
    };
    // Radius 1e-6: no segment crosses a disc of a micrometre, nothing is that near a vertex.
    for (auto kind : {EstimatorKind::Detp, EstimatorKind::PhotonMap}) {
        const auto E = estimate(scene, cache, kind, 1e-6f, 5);
        EXPECT_TRUE(allFinite(E));
        EXPECT_EQ(largestComponent(E), 0.0f) << estimatorName(kind);
    }
    // Radius far larger than the scene, and k larger than the number of photons.
    EXPECT_TRUE(allFinite(estimate(scene, cache, EstimatorKind::Detp, 100.0f)));
    const auto many = estimate(scene, cache, EstimatorKind::PhotonMap, 100.0f, 1000000);
    EXPECT_TRUE(allFinite(many));
    EXPECT_GT(largestComponent(many), 0.0f);
    // Zero photons reaching a vertex: the cube's underside rests on the floor... the floor's
    // vertices under the cube see no light at a small radius.
    const auto shadowed = estimate(scene, cache, EstimatorKind::Detp, 0.01f);
    const auto pmShadowed = estimate(scene, cache, EstimatorKind::PhotonMap, 0.01f);
    const auto ic = estimate(scene, cache, EstimatorKind::ImpactCount, 0.0f);
    size_t dark = 0;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3f p = Vec3f(Vec3d(scene.positions[v]) + scene.worldOrigin);
        if (std::fabs(p.x) < 0.2f && std::fabs(p.z) < 0.2f && p.y == 0.0f) {
            EXPECT_EQ(shadowed[v], Vec3f(0.0f));
            EXPECT_EQ(pmShadowed[v], Vec3f(0.0f));
            EXPECT_EQ(ic[v], Vec3f(0.0f));
            ++dark;
        }
    }
    EXPECT_GT(dark, 0u);
    // No photons at all in the cache.
    const RayCache empty;
    EXPECT_TRUE(allFinite(estimate(scene, empty, EstimatorKind::Detp, 0.1f)));
    EXPECT_TRUE(allFinite(estimate(scene, empty, EstimatorKind::PhotonMap, 0.1f)));
}
