// Where discs meet other geometry (docs/design.md §5, issue 7): no leaks through thin occluders, no light
// lost or gained at borders, curved surfaces, crease fallbacks, and flat interiors unchanged. Black
// surfaces make the irradiance the direct light, which is analytic.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "estimate/disc_regions.h"
#include "estimate/estimator.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "trace/photon_tracer.h"

using namespace qsgi;

namespace {

RayCache trace(const Scene& scene, uint64_t photons) { return traceScene(scene, photons, 5); }

std::vector<Vec3f> estimate(const Scene& scene, const RayCache& cache, EstimatorKind kind, DetpBoundary rule,
                            float radius, int k = 50) {
    return estimateWith(scene, cache, NamedEstimator{"", kind, rule}.settings(radius, k)).irradiance;
}

Vec3d worldPosition(const Scene& s, size_t v) { return Vec3d(s.positions[v]) + s.worldOrigin; }

// Direct irradiance from a point light of intensity 1 W/sr at `light` on a surface with normal n.
double pointIrradiance(const Vec3d& light, const Vec3d& p, const Vec3d& n) {
    const Vec3d d = light - p;
    const double len = length(d);
    return std::max(0.0, dot(d, n)) / (len * len * len);
}

const NamedEstimator kLeakFree[] = {{"DETP clip", EstimatorKind::Detp, DetpBoundary::Clip},
                           {"DETP linear", EstimatorKind::Detp, DetpBoundary::Linear},
                           {"photon map", EstimatorKind::PhotonMap, DetpBoundary::Clip},
                           {"impact count", EstimatorKind::ImpactCount, DetpBoundary::Clip}};

// Every leak-free estimator gives exactly zero at `dark`; returns the paper rule's mean there.
double expectNoLightAt(const Scene& scene, const RayCache& cache, const std::vector<size_t>& dark, float r) {
    for (const NamedEstimator& e : kLeakFree) {
        const auto E = estimate(scene, cache, e.kind, e.rule, r);
        size_t lit = 0;
        for (size_t v : dark) lit += E[v] != Vec3f(0.0f);
        EXPECT_EQ(lit, 0u) << e.name << " gives light at " << lit << " of " << dark.size() << " vertices that receive none";
    }
    const auto paper = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Paper, r);
    double mean = 0;
    for (size_t v : dark) mean += paper[v].y / double(dark.size());
    return mean;
}

}  // namespace

// A plate 5 mm above a black floor under a point light: floor vertices farther than r inside the
// plate's outline are in its shadow, and every estimator must give exactly zero there (photons on
// the plate's top are 5 mm in front of the floor's plane, far beyond its band ε⁺).
TEST(DetpBoundary, ThinPlateOverAFloorLeaksNothing) {
    const float r = 0.05f, half = 0.4f;
    Scene scene = testscenes::plateOverFloor(64, half, 0.005f, Vec3f(0.0f));
    testscenes::addPointLight(scene, Vec3f(0.1f, 1.0f, 0.0f), Vec3f(1.0f));
    const RayCache cache = trace(scene, 400000);
    std::vector<size_t> shaded;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d p = worldPosition(scene, v);
        if (p.y == 0 && std::fabs(p.x) < half - r - 0.01 && std::fabs(p.z) < half - r - 0.01) shaded.push_back(v);
    }
    ASSERT_GT(shaded.size(), 50u);
    const double leaked = expectNoLightAt(scene, cache, shaded, r);
    std::printf("plate 5 mm over a floor: mean E under it, paper rule %.4f W/m^2 (every other rule: 0)\n", leaked);
    EXPECT_GT(leaked, 0.0) << "the paper rule was expected to show the leak";
}

// A zero-thickness wall standing on a black floor, the light on its +z side: floor vertices on
// the −z side within r of the wall receive no direct light, and no estimator may count the lit
// side's photons (their crossings fall in cells behind the wall).
TEST(DetpBoundary, ThinPartitionKeepsTheOtherSidesLight) {
    const float r = 0.1f;
    Scene scene = testscenes::partition(64, Vec3f(0.0f));
    testscenes::addPointLight(scene, Vec3f(0.0f, 0.5f, 0.5f), Vec3f(1.0f));
    const RayCache cache = trace(scene, 400000);
    std::vector<size_t> dark;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d p = worldPosition(scene, v);
        if (p.y == 0 && p.z < 0 && p.z > -r && std::fabs(p.x) < 0.9) dark.push_back(v);
    }
    ASSERT_GT(dark.size(), 20u);
    const double leaked = expectNoLightAt(scene, cache, dark, r);
    std::printf("thin partition: mean E beside it on the dark side, paper rule %.4f W/m^2 (every other rule: 0)\n", leaked);
}

// The test scene of the issue: a light slab hanging 4 mm under the ceiling of a white box. The
// ceiling above the slab's middle receives only what comes through the gap. Impact count has no
// leak by construction (it counts impacts on the ceiling's own triangles), so the estimators
// must agree with it there within the noise: σ of a region mean from the photons' powers,
// sqrt(ΣΦ²)/ΣΦ, for each side, 4σ allowed.
TEST(DetpBoundary, CeilingAboveALightPanelSeesOnlyTheGap) {
    Warnings w;
    const Scene scene = loadGltfScene((sourceDir() / "tests/scenes/ceiling_panel/ceiling_panel.gltf").string(), w);
    const float r = 0.05f;
    const RayCache cache = trace(scene, 1000000);
    std::vector<size_t> above;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d p = worldPosition(scene, v);
        if (p.y == 2.0 && std::fabs(p.x) < 0.2 && std::fabs(p.z) < 0.2) above.push_back(v);
    }
    ASSERT_GT(above.size(), 10u);
    // Noise of a region mean: impacts on the ceiling within the region grown by r.
    double sum = 0, sumSq = 0;
    cache.forEachSegment([&](const Segment& s) {
        if (!s.hasImpact()) return;
        const Vec3d h = Vec3d(s.impactPoint()) + scene.worldOrigin;
        if (std::fabs(h.y - 2.0) < 1e-4 && std::fabs(h.x) < 0.2 + r && std::fabs(h.z) < 0.2 + r) {
            sum += s.power.y;
            sumSq += double(s.power.y) * s.power.y;
        }
    });
    ASSERT_GT(sum, 0.0) << "no light reaches the ceiling through the gap: the test would prove nothing";
    const double relativeSigma = std::sqrt(sumSq) / sum;
    auto regionMean = [&](const std::vector<Vec3f>& E) {
        double m = 0;
        for (size_t v : above) m += E[v].y / double(above.size());
        return m;
    };
    const double reference = regionMean(estimate(scene, cache, EstimatorKind::ImpactCount, DetpBoundary::Clip, r));
    for (const NamedEstimator& e : kLeakFree) {
        if (e.kind == EstimatorKind::ImpactCount) continue;
        const double m = regionMean(estimate(scene, cache, e.kind, e.rule, r));
        std::printf("ceiling above the panel: %s %.4f, impact count %.4f (relative σ %.3f)\n", e.name, m, reference, relativeSigma);
        EXPECT_NEAR(m, reference, 4 * 2 * relativeSigma * reference) << e.name;
    }
    const double paper = regionMean(estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Paper, r));
    std::printf("ceiling above the panel: DETP paper %.4f (%+.0f %%)\n", paper, 100 * (paper / reference - 1));
}

// An inside corner (black floor y = 0 and wall z = 0, a point light at three heights declared
// before measuring: steep, 45°, grazing). Vertices on the edge see half a reachable disc:
//   - `linear` fits the gradient, so its mean over the edge and near-edge vertices must lie within
//     5 % of the analytic irradiance (the bound);
//   - `clip` averages E over the reachable half disc, whose centroid lies 4r/(3π) into the
//     surface: its first-order bias is (∂E/∂u / E)·4r/(3π) (u pointing away from the edge). The
//     measured mean bias on the edge must match that prediction within half of it plus 4σ;
//   - the photon map covers only the half disc too (with r_k ≤ r), so its bias is bounded by
//     the same prediction, allowed 1.5× plus 4σ.
// σ of a group mean: per-vertex Poisson σ (photons in the half disc, or k for the photon map)
// over the number of independent discs along the edge (its length / 2r, on each surface).
TEST(DetpBoundary, InsideCornerEdgesAreUnbiasedWithLinearAndFirstOrderWithClip) {
    const float r = 0.1f;
    const double halfLength = 0.8;
    // The corner is 0.5 m deep (floor and wall), not 2 m: every disc measured lies within r of
    // the edge, and nothing beyond 2r of it reaches one (black surfaces, a point light), so the
    // other 1.5 m only cost photons and vertices. The photons are those of the 2 m corner (2·10⁶,
    // aimed: about half of them land, as many as 4·10⁶ unaimed) times the share of its aimed solid
    // angle that the 0.5 m corner keeps (0.175, 0.301, 0.176 for the three lights), rounded up: as
    // many photons per steradian, so φ0 and σ are those of the 2 m corner, or smaller.
    for (const auto& [light, photons] : {std::pair{Vec3d(0.0, 1.5, 0.5), uint64_t(360000)},
                                         std::pair{Vec3d(0.0, 1.0, 1.0), uint64_t(610000)},
                                         std::pair{Vec3d(0.0, 0.5, 1.5), uint64_t(360000)}}) {
        // 64 cells per 2 m: the noise of an edge mean is set by the independent discs along the
        // edge, not by how many vertices sample them, and each estimate costs vertices × crossings.
        Scene scene = testscenes::corner(64, Vec3f(0.0f), 0.5f);
        testscenes::addPointLight(scene, Vec3f(light), Vec3f(1.0f));
        const RayCache cache = trace(scene, photons);
        std::printf("inside corner, light (%.1f, %.1f, %.1f): %llu photons, φ0 %.4g\n", light.x, light.y, light.z,
                    static_cast<unsigned long long>(photons), double(cache.maxPhotonPower));
        const double phi0 = cache.maxPhotonPower;  // I Ω/N: the solid angle aimed at the corner
        const auto clip = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Clip, r);
        const auto linear = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Linear, r);
        const auto paper = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Paper, r);
        const auto pm = estimate(scene, cache, EstimatorKind::PhotonMap, DetpBoundary::Clip, r, 50);
        struct Group {
            double clip = 0, linear = 0, paper = 0, pm = 0, prediction = 0, variance = 0;
            int n = 0;
        } edge, near;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = worldPosition(scene, v);
            const bool floor = scene.normals[v].y > 0.5f;
            const double distance = floor ? p.z : p.y;
            if (std::fabs(p.x) > halfLength || distance > r) continue;
            const Vec3d n = floor ? Vec3d(0, 1, 0) : Vec3d(0, 0, 1), u = floor ? Vec3d(0, 0, 1) : Vec3d(0, 1, 0);
            const double truth = pointIrradiance(light, p, n);
            Group& g = distance == 0 ? edge : near;
            g.clip += clip[v].y / truth - 1;
            g.linear += linear[v].y / truth - 1;
            g.paper += paper[v].y / truth - 1;
            g.pm += pm[v].y / truth - 1;
            const double h = 1e-4;
            const double slope = (pointIrradiance(light, p + u * h, n) - pointIrradiance(light, p - u * h, n)) / (2 * h);
            g.prediction += slope / truth * 4 * r / (3 * M_PI);
            g.variance += phi0 / (truth * 0.5 * M_PI * r * r);  // Poisson: 1 / photons in the half disc
            ++g.n;
        }
        const double independent = 2 * (2 * halfLength) / (2 * r);
        for (Group* g : {&edge, &near}) {
            g->clip /= g->n, g->linear /= g->n, g->paper /= g->n, g->pm /= g->n, g->prediction /= g->n;
            g->variance /= g->n;
        }
        const double sigma = std::sqrt(edge.variance / independent), sigmaPm = std::sqrt(1.0 / 50 / independent);
        std::printf("inside corner, light (%.1f, %.1f, %.1f), r = %.2f, mean relative bias on the edge (%d vertices): "
                    "linear %+.4f, clip %+.4f (first-order prediction %+.4f, σ %.4f), photon map %+.4f, paper %+.4f; "
                    "within r of the edge (%d): linear %+.4f, clip %+.4f, photon map %+.4f, paper %+.4f\n",
                    light.x, light.y, light.z, r, edge.n, edge.linear, edge.clip, edge.prediction, sigma, edge.pm,
                    edge.paper, near.n, near.linear, near.clip, near.pm, near.paper);
        EXPECT_LT(std::fabs(edge.linear), 0.05);
        EXPECT_LT(std::fabs(near.linear), 0.05);
        EXPECT_NEAR(edge.clip, edge.prediction, 0.5 * std::fabs(edge.prediction) + 4 * sigma);
        EXPECT_LT(std::fabs(edge.pm), 1.5 * std::fabs(edge.prediction) + 4 * sigmaPm);
    }
}

// A black floor ending in the void, lit from above: the discs on its open border are fully
// reachable, and photons passing beside the border keep going and cross them, so DETP is
// unbiased there (to second order: r²|E''|/8E, well under 0.5 % here). σ as above, over the
// border's length / 2r discs; 4σ + 0.5 % allowed.
TEST(DetpBoundary, OpenEdgeOfAFloorIsUnbiased) {
    const float r = 0.1f, half = 1.6f;
    // Only the outer 0.4 m of the 3.2 m floor (16 of its 128 cells a side): the measured discs
    // lie within r of the outer border, and nothing beyond 2r of it reaches one (a black floor, a
    // point light), so the inside only cost vertices and the photons landing there. The photons
    // are the whole floor's (2·10⁶, aimed) times the share of its aimed solid angle the frame
    // keeps (0.757), rounded up: φ0, hence σ, is the whole floor's or smaller.
    const uint64_t photons = 1520000;
    Scene scene = testscenes::squareFrame(half, 128, 16, Vec3f(0.0f));
    const Vec3d light(0, 1, 0);
    testscenes::addPointLight(scene, Vec3f(light), Vec3f(1.0f));
    const RayCache cache = trace(scene, photons);
    const double phi0 = cache.maxPhotonPower;  // I Ω/N: the solid angle aimed at the floor
    std::printf("open edge of a floor: %llu photons, φ0 %.4g\n", static_cast<unsigned long long>(photons), phi0);
    for (DetpBoundary rule : {DetpBoundary::Clip, DetpBoundary::Linear, DetpBoundary::Paper}) {
        const auto E = estimate(scene, cache, EstimatorKind::Detp, rule, r);
        double bias = 0, variance = 0;
        int n = 0;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = worldPosition(scene, v);
            const bool border = std::fabs(std::fabs(p.x) - half) < 1e-4 || std::fabs(std::fabs(p.z) - half) < 1e-4;
            if (!border || std::min(std::fabs(p.x), std::fabs(p.z)) > 1.0) continue;
            const double truth = pointIrradiance(light, p, Vec3d(0, 1, 0));
            bias += E[v].y / truth - 1;
            variance += phi0 / (truth * M_PI * r * r);
            ++n;
        }
        bias /= n;
        const double sigma = std::sqrt(variance / n / (4 * 2.0 / (2 * r)));
        std::printf("open edge of a floor, DETP %s: mean relative bias %+.4f over %d border vertices (σ %.4f)\n",
                    detpBoundaryName(rule), bias, n, sigma);
        if (rule != DetpBoundary::Paper) {
            EXPECT_LT(std::fabs(bias), 4 * sigma + 0.005) << detpBoundaryName(rule);
        }
    }
}

// A black box standing on a black floor: a floor vertex beside it must neither lose light (the
// area under the box is no part of its disc) nor gain any (no crossing under the box counts).
// `clip`'s expectation is then the mean of the analytic irradiance (with the box's shadow) over
// the cells whose centres lie outside the box's footprint, which this test integrates on its own
// (4×4 sub-points per cell); the group mean must match it within 4σ (Poisson, per vertex, over
// the independent discs along the box's sides).
TEST(DetpBoundary, FloorBesideABoxNeitherLosesNorGainsLightFromUnderIt) {
    const float r = 0.1f;
    // The floor is 1.5 m a side, not 4 m (36 cells, the 4 m floor's 96-cell spacing): the
    // measured vertices lie within h + r = 0.4 of the centre, and nothing beyond 2r of them
    // reaches their discs (black surfaces, a point light), so the rest only cost vertices and
    // photons. The photons are the 4 m floor's (2·10⁶) times the share of its aimed solid angle the
    // 1.5 m floor keeps (0.288), rounded up: φ0, hence σ, is the 4 m floor's or smaller.
    const uint64_t photons = 580000;
    Scene scene = testscenes::boxOnFloor(36, 12, Vec3f(0.0f), 0.75f);
    const Vec3d light(0.8, 1.5, 0.6);
    testscenes::addPointLight(scene, Vec3f(light), Vec3f(1.0f));
    const RayCache cache = trace(scene, photons);
    const double phi0 = cache.maxPhotonPower, h = 0.3;  // I Ω/N: the solid angle aimed at the scene
    std::printf("floor beside a box: %llu photons, φ0 %.4g\n", static_cast<unsigned long long>(photons), phi0);
    const auto clip = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Clip, r);
    const auto paper = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Paper, r);
    auto insideFootprint = [&](double x, double z) { return std::fabs(x) < h && std::fabs(z) < h; };
    auto lit = [&](const Vec3d& p) {  // slab test of the segment p → light against the cube
        double t0 = 0, t1 = 1;
        const Vec3d d = light - p, lo(-h, 0, -h), hi(h, 2 * h, h);
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0) {
                if (p[a] < lo[a] || p[a] > hi[a]) return true;
                continue;
            }
            double ta = (lo[a] - p[a]) / d[a], tb = (hi[a] - p[a]) / d[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta), t1 = std::min(t1, tb);
        }
        return t0 > t1 || t1 <= 1e-9;
    };
    double measured = 0, paperMean = 0, variance = 0;
    int n = 0;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d p = worldPosition(scene, v);
        if (scene.normals[v].y < 0.5f) continue;  // floor vertices only (the box's sides reach y = 0 too)
        if (insideFootprint(p.x, p.z) || std::fabs(p.x) > h + r || std::fabs(p.z) > h + r) continue;
        if (std::fabs(p.x) > h - 0.05 && std::fabs(p.z) > h - 0.05) continue;  // not beside a corner
        Vec3f tangent, bitangent;
        discFrame(scene.normals[v], tangent, bitangent);
        double sum = 0;
        int samples = 0;
        for (int c = 0; c < kDiscCells; ++c) {
            double cx, cy;
            discCellCentre(c, cx, cy);
            const Vec3d centre = p + (Vec3d(tangent) * cx + Vec3d(bitangent) * cy) * double(r);
            if (insideFootprint(centre.x, centre.z)) continue;
            const int ring = c / kDiscSectors, sector = c % kDiscSectors;
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) {
                    const double rho = std::sqrt((ring + (i + 0.5) / 4) / kDiscRings) * r;
                    const double phi = 2 * M_PI * (sector + (j + 0.5) / 4) / kDiscSectors;
                    const Vec3d q = p + (Vec3d(tangent) * std::cos(phi) + Vec3d(bitangent) * std::sin(phi)) * rho;
                    sum += lit(q) ? pointIrradiance(light, q, Vec3d(0, 1, 0)) : 0;
                    ++samples;
                }
        }
        if (samples == 0) continue;
        const double e = sum / samples;
        if (!(e > 0)) continue;
        measured += clip[v].y / e - 1;
        paperMean += paper[v].y / e - 1;
        variance += phi0 / (e * M_PI * r * r * samples / (16.0 * kDiscCells));
        ++n;
    }
    ASSERT_GT(n, 50);
    measured /= n, paperMean /= n;
    const double sigma = std::sqrt(variance / n / (4 * 2 * h / (2 * r)));
    std::printf("floor beside a box (%d vertices): clip vs its expectation %+.4f (σ %.4f); paper rule vs the same %+.4f\n",
                n, measured, sigma, paperMean);
    EXPECT_LT(std::fabs(measured), 4 * sigma);
}

// A welded L-shaped sheet with a 90° crease and area-weighted normals: the crease vertices'
// normals are 45° from both faces, so their own surface is empty and they fall back to the paper
// rule (finite, counted). (The two ends of the crease have one more triangle on one side, so
// their normals lean toward it and keep an own surface.) Every vertex off the crease must get
// exactly what it gets when the crease is split into two rows with face normals: the fallback
// does not spill onto the neighbours.
TEST(DetpBoundary, CreaseVerticesFallBackAndLeaveTheirNeighboursAlone) {
    const int cells = 32;
    const float r = 0.1f;
    Scene welded = testscenes::creasedSheet(cells, true, Vec3f(0.0f));
    Scene split = testscenes::creasedSheet(cells, false, Vec3f(0.0f));
    for (Scene* s : {&welded, &split}) testscenes::addPointLight(*s, Vec3f(0.2f, 0.7f, 0.6f), Vec3f(1.0f));
    const RayCache cw = trace(welded, 300000), cs = trace(split, 300000);
    ASSERT_EQ(cw.segmentCount(), cs.segmentCount());
    EmbreeDevice device;
    const SceneBvh bvh(device, welded);
    DiscRegions regions(r, false);
    regions.computeAll(welded, bvh);
    auto onCrease = [&](size_t v) {
        const Vec3d p = worldPosition(welded, v);
        return p.y == 0 && p.z == 0;
    };
    size_t fallbacks = 0;
    for (size_t v = 0; v < welded.vertexCount(); ++v) {
        if (!regions[v].fallback) continue;
        EXPECT_TRUE(onCrease(v)) << "vertex " << v << " falls back but is not on the crease";
        ++fallbacks;
    }
    EXPECT_EQ(fallbacks, size_t(cells - 1)) << "every crease vertex but the two ends";
    EXPECT_EQ(regions.fallbackVertices(), fallbacks);
    for (const NamedEstimator& e : kLeakFree) {
        if (e.kind == EstimatorKind::ImpactCount) continue;
        const auto Ew = estimate(welded, cw, e.kind, e.rule, r), Es = estimate(split, cs, e.kind, e.rule, r);
        size_t compared = 0;
        for (size_t v = 0; v < welded.vertexCount(); ++v) {
            ASSERT_TRUE(isFinite(Ew[v])) << e.name << " vertex " << v;
            if (onCrease(v)) continue;
            ASSERT_EQ(welded.positions[v], split.positions[v]);
            EXPECT_EQ(Ew[v], Es[v]) << e.name << " vertex " << v << " changed because its neighbour is a crease";
            ++compared;
        }
        EXPECT_EQ(compared, welded.vertexCount() - size_t(cells + 1));
    }
}

// Where the whole disc is reachable and no other geometry lies within r, `clip` and `linear`
// count exactly the crossings the published rule counts over exactly its area: identical bits.
TEST(DetpBoundary, FlatInteriorsAreIdenticalToThePaperRule) {
    const float r = 0.08f, half = 1.6f;
    Scene scene = testscenes::plane(half, 64, Vec3f(0.0f));
    testscenes::addPointLight(scene, Vec3f(0.3f, 1.0f, -0.2f), Vec3f(1.0f));
    const RayCache cache = trace(scene, 300000);
    const auto paper = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Paper, r);
    const auto clip = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Clip, r);
    const auto linear = estimate(scene, cache, EstimatorKind::Detp, DetpBoundary::Linear, r);
    size_t interior = 0;
    for (size_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d p = worldPosition(scene, v);
        if (std::max(std::fabs(p.x), std::fabs(p.z)) > half - r - 0.01) continue;
        ASSERT_EQ(clip[v], paper[v]) << "vertex " << v;
        ASSERT_EQ(linear[v], paper[v]) << "vertex " << v;
        ++interior;
    }
    EXPECT_GT(interior, 3000u);
}

// Outside of a black unit sphere under a point light 2.5 m from its centre: E = I cosθ/d² on the
// lit side. Vertices with cosθ > 0.5 (away from the terminator, where E has a kink) must average
// within 1 % of it for DETP (clip, linear) and the photon map; σ of that mean is ~0.2 % here.
TEST(DetpBoundary, OutsideOfASphereIsUnbiasedWithinOnePercent) {
    Scene scene = testscenes::closedSphere(1.0f, 5, Vec3f(0.0f), false);
    const Vec3d light(0, 2.5, 0);
    testscenes::addPointLight(scene, Vec3f(light), Vec3f(1.0f));
    const RayCache cache = trace(scene, 4000000);
    for (const NamedEstimator& e : kLeakFree) {
        if (e.kind == EstimatorKind::ImpactCount) continue;
        const auto E = estimate(scene, cache, e.kind, e.rule, e.kind == EstimatorKind::PhotonMap ? 0.2f : 0.05f);
        double bias = 0;
        int n = 0;
        for (size_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = worldPosition(scene, v), normal = normalize(p);
            const Vec3d toLight = normalize(light - p);
            if (dot(toLight, normal) < 0.5) continue;
            bias += E[v].y / pointIrradiance(light, p, normal) - 1;
            ++n;
        }
        bias /= n;
        std::printf("outside of a sphere, %s: mean relative bias %+.4f over %d lit vertices\n", e.name, bias, n);
        EXPECT_LT(std::fabs(bias), 0.01) << e.name;
    }
}
