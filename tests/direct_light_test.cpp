// Exact direct light (DirectLight, docs/design.md §5.1): punctual lights against I cosθ / d² and
// E cosθ at every vertex (shadow rays from its start, a float error off v), with shadows decided analytically; a parallel rectangular
// emitter against the closed-form configuration factor, its quasi-random error bounded by the
// Monte Carlo error of the same estimator, unbiased, and falling with the sample count.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "estimate/direct_light.h"
#include "estimate/disc_regions.h"
#include "estimate/vertex_starts.h"
#include "scene/environment_light.h"
#include "test_support.h"
#include "trace/scene_bvh.h"

using namespace qsgi;

namespace {

using Rig = SecondPassRig;

std::vector<Vec3f> directLight(const Scene& scene, const Rig& rig, uint32_t samples, uint64_t seed = 7) {
    DirectLight direct(samples, seed);
    direct.computeAll(scene, rig.bvh, rig.starts);
    return direct.irradiance();
}

// DirectLight sums in double and stores a float: the stored value is the double sum rounded once,
// relative error ≤ 2^-24. The expected values below are the same double expressions from the same
// floats (start, normal, light), so they differ from the code's sum by a few double roundings
// (~1e-16). Allowing 4 · 2^-24 leaves room for nothing else.
constexpr double kFloatTolerance = 4 * 0x1p-24;

void expectRelativelyEqual(const Vec3f& got, const Vec3d& want, double tolerance, const char* what, uint32_t v) {
    for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(double(got[c]), want[c], tolerance * std::abs(want[c])) << what << ", vertex " << v << ", channel " << c;
}

PunctualLight light(const Scene& scene, LightType type, Vec3f position, Vec3f direction, Vec3f intensity, float cosOuter = 0) {
    PunctualLight l;
    l.name = "test light";
    l.type = type;
    l.position = Vec3f(Vec3d(position) - scene.worldOrigin);
    l.direction = normalize(direction);
    l.intensity = intensity;
    l.cosOuterCone = cosOuter;
    return l;
}

// I cosθ / d² at the point with normal n, as the header defines it at v (0 if the light is behind).
Vec3d pointIrradiance(const PunctualLight& l, const Vec3f& at, const Vec3f& normal) {
    const Vec3d d = Vec3d(l.position) - Vec3d(at);
    const double d2 = dot(d, d), dist = std::sqrt(d2);
    const double cosV = dot(Vec3d(normal), d / dist);
    return cosV > 0 ? Vec3d(l.intensity) * (cosV / d2) : Vec3d(0.0);
}

struct Box2 {
    double x0 = 1e30, x1 = -1e30, z0 = 1e30, z1 = -1e30, y = 0;
};
// The x–z extent and height of an axis-aligned horizontal instance (scene coordinates).
Box2 horizontalExtent(const Scene& scene, size_t instance) {
    const MeshInstance& in = scene.instances[instance];
    Box2 b;
    for (uint32_t v = in.firstVertex; v < in.firstVertex + in.vertexCount; ++v) {
        const Vec3f& p = scene.positions[v];
        b.x0 = std::min(b.x0, double(p.x)), b.x1 = std::max(b.x1, double(p.x));
        b.z0 = std::min(b.z0, double(p.z)), b.z1 = std::max(b.z1, double(p.z));
        b.y = p.y;
    }
    return b;
}

// Where the ray s + t·w (t in (0, tmax)) crosses the plane y = box.y: inside the box, outside, or
// within `margin` of its edge (undecided). Rays that do not reach the plane are outside.
enum class Crossing { Inside, Outside, NearEdge };
Crossing crossing(const Box2& box, const Vec3d& s, const Vec3d& w, double tmax, double margin) {
    if (w.y == 0) return Crossing::Outside;
    const double t = (box.y - s.y) / w.y;
    if (!(t > 0) || !(t < tmax)) return Crossing::Outside;
    const double x = s.x + t * w.x, z = s.z + t * w.z;
    const double inside = std::min({x - box.x0, box.x1 - x, z - box.z0, box.z1 - z});  // > 0 inside
    if (std::abs(inside) < margin) return Crossing::NearEdge;
    return inside > 0 ? Crossing::Inside : Crossing::Outside;
}

// Margin around a shadow's edge: the start points lie 1e-6 of the scene's diagonal off the
// vertices (ε⁺ and the side step), float directions and Embree's watertight test err by ~1e-7 of
// the distances here (≤ 2 m). 1e-4 m is far beyond all of that.
constexpr double kEdgeMargin = 1e-4;

double seconds(std::chrono::steady_clock::time_point since) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

// A point light over a plane: every vertex's D_v is I cosθ / d² at the vertex itself (distance and
// cosine from v; only the shadow ray leaves from the start point s_v, a float error off v).
TEST(DirectLight, PointLightOverPlaneIsInverseSquareCosine) {
    const auto start = std::chrono::steady_clock::now();
    Scene scene = testscenes::plane(1.0f, 32, Vec3f(0.5f));
    scene.lights.push_back(light(scene, LightType::Point, {0.2f, 0.8f, -0.1f}, {0, -1, 0}, {3.0f, 2.0f, 1.0f}));
    const Rig rig(scene);
    const std::vector<Vec3f> D = directLight(scene, rig, 16);
    ASSERT_EQ(D.size(), scene.vertexCount());
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        expectRelativelyEqual(D[v], pointIrradiance(scene.lights[0], scene.positions[v], rig.starts.normal(v)),
                              kFloatTolerance, "at the vertex", v);
    }
    std::printf("point light over a plane: %zu vertices, %.2f s\n", scene.vertexCount(), seconds(start));
}

// An opaque plate between the light and the floor: a vertex whose segment to the light crosses the
// plate gets exactly 0, every other exactly the unoccluded value (vertices within kEdgeMargin of
// the shadow's edge are skipped). Visibility is decided from the plate's own vertices.
TEST(DirectLight, PointLightShadowOfAPlateIsExact) {
    const auto start = std::chrono::steady_clock::now();
    Scene scene = testscenes::plateOverFloor(48, 0.25f, 0.3f, Vec3f(0.5f));
    scene.lights.push_back(light(scene, LightType::Point, {0.1f, 1.0f, 0.05f}, {0, -1, 0}, Vec3f(2.0f)));
    const Rig rig(scene);
    const std::vector<Vec3f> D = directLight(scene, rig, 16);
    const Box2 plate = horizontalExtent(scene, 1);
    const PunctualLight& l = scene.lights[0];
    size_t shadowed = 0, lit = 0, skipped = 0;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3f s = rig.starts.point(v);
        const Vec3d d = Vec3d(l.position) - Vec3d(s);
        const double dist = length(d);
        const Crossing c = crossing(plate, Vec3d(s), d / dist, dist, kEdgeMargin);
        if (c == Crossing::NearEdge) {
            ++skipped;
            continue;
        }
        if (c == Crossing::Inside) {
            ++shadowed;
            ASSERT_EQ(D[v], Vec3f(0.0f)) << "vertex " << v << " is in the plate's shadow";
        } else {
            ++lit;
            expectRelativelyEqual(D[v], pointIrradiance(l, scene.positions[v], rig.starts.normal(v)), kFloatTolerance, "lit", v);
        }
    }
    std::printf("plate's shadow: %zu shadowed, %zu lit, %zu at the edge skipped, %.2f s\n", shadowed, lit, skipped,
                seconds(start));
    EXPECT_GT(shadowed, 100u);
    EXPECT_GT(lit, 1000u);
    EXPECT_LT(skipped, 10u);
}

// A spot light: I cosθ / d² inside its outer cone, exactly 0 outside (no smooth falloff: its
// photons fill the outer cone uniformly). Vertices whose direction from the light is within 1e-6
// of the cone's cosine are skipped (the code and this test evaluate the same double expression;
// 1e-6 covers any difference in rounding).
TEST(DirectLight, SpotLightIsZeroOutsideItsConeAndInverseSquareCosineInside) {
    Scene scene = testscenes::plane(1.0f, 48, Vec3f(0.5f));
    const float cosOuter = float(std::cos(25.0 * M_PI / 180.0));
    scene.lights.push_back(light(scene, LightType::Spot, {0.1f, 1.0f, 0.0f}, {0.2f, -1.0f, 0.1f}, {1.0f, 2.0f, 3.0f}, cosOuter));
    const Rig rig(scene);
    const std::vector<Vec3f> D = directLight(scene, rig, 16);
    const PunctualLight& l = scene.lights[0];
    size_t inside = 0, outside = 0;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d d = Vec3d(scene.positions[v]) - Vec3d(l.position);
        const double cosAxis = dot(d / length(d), Vec3d(l.direction));
        if (std::abs(cosAxis - double(cosOuter)) < 1e-6) continue;
        if (cosAxis < double(cosOuter)) {
            ++outside;
            ASSERT_EQ(D[v], Vec3f(0.0f)) << "vertex " << v << " lies outside the cone";
        } else {
            ++inside;
            expectRelativelyEqual(D[v], pointIrradiance(l, scene.positions[v], rig.starts.normal(v)), kFloatTolerance, "in the cone", v);
        }
    }
    EXPECT_GT(inside, 300u);
    EXPECT_GT(outside, 300u);
}

// A directional light: E cosθ at every vertex of a plane, and with a plate over the floor exactly 0
// where the ray from the start against the light's direction crosses the plate.
TEST(DirectLight, DirectionalLightIsIrradianceTimesCosineAndShadowedExactly) {
    const Vec3f direction = normalize(Vec3f(0.3f, -1.0f, 0.2f));
    for (const bool withPlate : {false, true}) {
        SCOPED_TRACE(withPlate ? "plate over floor" : "plane");
        Scene scene = withPlate ? testscenes::plateOverFloor(48, 0.25f, 0.3f, Vec3f(0.5f)) : testscenes::plane(1.0f, 32, Vec3f(0.5f));
        scene.lights.push_back(light(scene, LightType::Directional, {0, 0, 0}, direction, {2.0f, 1.0f, 0.5f}));
        const Rig rig(scene);
        const std::vector<Vec3f> D = directLight(scene, rig, 16);
        const PunctualLight& l = scene.lights[0];
        const Box2 plate = withPlate ? horizontalExtent(scene, 1) : Box2{};
        size_t shadowed = 0, lit = 0;
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d w = -Vec3d(l.direction);
            const double cosV = dot(Vec3d(rig.starts.normal(v)), w);
            const Vec3d expected = Vec3d(l.intensity) * cosV;
            const Crossing c = withPlate ? crossing(plate, Vec3d(rig.starts.point(v)), w, 1e30, kEdgeMargin) : Crossing::Outside;
            if (c == Crossing::NearEdge) continue;
            if (c == Crossing::Inside) {
                ++shadowed;
                ASSERT_EQ(D[v], Vec3f(0.0f)) << "vertex " << v;
            } else {
                ++lit;
                expectRelativelyEqual(D[v], expected, kFloatTolerance, "directional", v);
            }
        }
        if (withPlate) {
            EXPECT_GT(shadowed, 100u);
        }
        EXPECT_GT(lit, 1000u);
    }
}

namespace {

// Configuration factor from a differential element to a parallel rectangle with one corner right
// above it (height c, sides a and b): F = 1/(2π) [A/√(1+A²) atan(B/√(1+A²)) + B/√(1+B²) atan(A/√(1+B²))],
// A = a/c, B = b/c. Odd in a and in b, so a rectangle [x0, x1] × [z0, z1] placed anywhere is
// f(x1, z1) − f(x0, z1) − f(x1, z0) + f(x0, z0) (coordinates relative to the element).
double cornerFactor(double a, double b, double c) {
    const double A = a / c, B = b / c, sa = std::sqrt(1 + A * A), sb = std::sqrt(1 + B * B);
    return (A / sa * std::atan(B / sa) + B / sb * std::atan(A / sb)) / (2 * M_PI);
}

double rectangleFactor(const Box2& r, const Vec3d& p) {
    const double c = r.y - p.y, x0 = r.x0 - p.x, x1 = r.x1 - p.x, z0 = r.z0 - p.z, z1 = r.z1 - p.z;
    return cornerFactor(x1, z1, c) - cornerFactor(x0, z1, c) - cornerFactor(x1, z0, c) + cornerFactor(x0, z0, c);
}

// The single-sample estimator DirectLight averages, for this scene: both triangles have the same
// area and radiance, so each is chosen with probability ½ and x is uniform on the rectangle,
// X = A L_e cosθ_v cosθ_e / d² = A L_e c² / d⁴. Returns {E[X] / L_e, E[X²] / L_e²} by the
// midpoint rule on n × n cells (smooth integrand, c ≥ 0.5 ≫ cell 2.3e-3: error ~1e-6 relative).
struct Moments {
    double mean, square;
};
Moments singleSampleMoments(const Box2& r, const Vec3d& p, int n = 256) {
    const double c = r.y - p.y, dx = (r.x1 - r.x0) / n, dz = (r.z1 - r.z0) / n, area = (r.x1 - r.x0) * (r.z1 - r.z0);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
            const double x = r.x0 + (i + 0.5) * dx - p.x, z = r.z0 + (j + 0.5) * dz - p.z;
            const double d2 = x * x + z * z + c * c, g = c * c / (d2 * d2);
            sum += g;
            sum2 += g * g;
        }
    // ∫ g dA / π is F (E = L_e ∫ g dA); E[X²] = A ∫ g² dA.
    return {sum * dx * dz, area * sum2 * dx * dz};
}

}  // namespace

// A floor under a parallel emissive rectangle (two triangles facing down, L_e = (1.5, 1, 0.5), 0.5 m
// up): D_v = π L_e F(s_v), F the closed-form factor above, at every floor vertex.
//
// The error bound. For S independent uniform samples the relative error of vertex v has variance
// r_v² / S, r_v = √(E[X²] − E[X]²) / E[X] the single-sample estimator's relative standard
// deviation, computed here by quadrature (singleSampleMoments). DirectLight's samples are a
// vertex's own Owen-scrambled Sobol points: unbiased, independent between vertices, and for a
// smooth integrand at least as accurate as independent samples (asymptotically far more). So the
// mean squared relative error over the N floor vertices must not exceed c² / S, c² = mean of r_v²;
// the test allows that plus four standard errors of the measured mean (the squared errors'
// sample standard deviation / √N), a one-sided test that fails by chance with probability ~3e-5.
// Unbiasedness: independent per-vertex errors make the mean error's standard error RMS/√N; the
// test allows 3 of them plus 2^-22 (the float result and the 24-bit uniforms). With 4096 samples
// every vertex must match the closed form to 0.5 %, and the RMS must fall at least 4-fold from S = 4
// to S = 64 (the independent-sample rate; the scrambled net only does better).
TEST(DirectLight, ParallelRectangularEmitterMatchesTheConfigurationFactor) {
    const auto start = std::chrono::steady_clock::now();
    const Vec3f emission(1.5f, 1.0f, 0.5f);
    Scene scene = testscenes::floorUnderEmitter(32, {0.1f, 0.5f, -0.05f}, 0.3f, 0.2f, emission, Vec3f(0.5f));
    const Rig rig(scene);
    const Box2 lamp = horizontalExtent(scene, 1);
    const MeshInstance& floor = scene.instances[0];
    const uint32_t n = floor.vertexCount;

    std::vector<double> exact(n), relStd2(n);
    double c2 = 0;
    for (uint32_t i = 0; i < n; ++i) {
        const Vec3d p(scene.positions[floor.firstVertex + i]);
        ASSERT_EQ(rig.starts.normal(floor.firstVertex + i), Vec3f(0, 1, 0));
        const double F = rectangleFactor(lamp, p);
        exact[i] = M_PI * F;  // per unit L_e
        const Moments m = singleSampleMoments(lamp, p);
        ASSERT_NEAR(m.mean, exact[i], 1e-5 * exact[i]) << "the closed form and the quadrature disagree at floor vertex " << i;
        relStd2[i] = (m.square - m.mean * m.mean) / (m.mean * m.mean);
        c2 += relStd2[i] / n;
    }
    std::printf("rectangle: %u floor vertices, F from %.4f to %.4f, iid relative std c = %.3f\n", n,
                *std::min_element(exact.begin(), exact.end()) / M_PI, *std::max_element(exact.begin(), exact.end()) / M_PI,
                std::sqrt(c2));

    auto rmsAt = [&](uint32_t S) {
        const std::vector<Vec3f> D = directLight(scene, rig, S, 11);
        double sum = 0, sum2 = 0, sum4 = 0, worst = 0;
        for (uint32_t i = 0; i < n; ++i) {
            const Vec3f& d = D[floor.firstVertex + i];
            // The channels share every sample: their ratios are the emission's, to float precision.
            EXPECT_NEAR(d.x / d.y, 1.5, 4 * 0x1p-24 * 1.5) << "vertex " << i;
            EXPECT_NEAR(d.z / d.y, 0.5, 4 * 0x1p-24 * 0.5) << "vertex " << i;
            const double e = double(d.y) / exact[i] - 1;
            sum += e, sum2 += e * e, sum4 += e * e * e * e;
            worst = std::max(worst, std::abs(e));
        }
        const double mean = sum / n, ms = sum2 / n, rms = std::sqrt(ms);
        const double msError = std::sqrt(std::max(0.0, sum4 / n - ms * ms) / n);
        const double iid = c2 / S;
        std::printf("  S = %4u: RMS relative error %.3e (iid %.3e, ratio %.3f), mean %+.2e, worst %.3e\n", S, rms,
                    std::sqrt(iid), rms / std::sqrt(iid), mean, worst);
        EXPECT_LE(ms, iid + 4 * msError) << "S = " << S << ": worse than independent samples";
        EXPECT_LT(std::abs(mean), 3 * rms / std::sqrt(double(n)) + 0x1p-22) << "S = " << S << ": biased";
        if (S >= 4096) {
            EXPECT_LT(worst, 0.005) << "S = " << S;
        }
        return rms;
    };
    const double rms4 = rmsAt(4);
    rmsAt(16);
    const double rms64 = rmsAt(64);
    rmsAt(4096);
    EXPECT_LT(rms64, rms4 / 4) << "the error does not fall with the sample count";
    std::printf("rectangle: %.2f s\n", seconds(start));
}

// A later frame finds the vertices whose shadow rays meet a mover's bounds (raysMeeting). The cone
// cull rules vertices out without making their rays; it must find exactly the vertices that making
// every vertex's rays finds, for finite emitters (lamps and point and spot lights, some under the
// floor), directional lights and an environment, boxes anywhere from a few centimetres to most of
// the scene. On the lamps alone a 10 cm box leaves most vertices' rays unmade.
TEST(DirectLight, TheConeCullFindsTheVerticesMakingEveryRayFinds) {
    for (const int lighting : {0, 1, 2}) {
        SCOPED_TRACE(lighting == 0 ? "lamps and lights" : lighting == 1 ? "lamps and two directional lights" : "lamps under a sky");
        Scene scene = testscenes::lampsOverBlocks(24, 12, lighting == 0 ? 8 : 0, 5);
        if (lighting == 1) {
            scene.lights.push_back(light(scene, LightType::Directional, {0, 0, 0}, normalize(Vec3f(0.3f, -1.0f, 0.2f)), Vec3f(1.0f)));
            scene.lights.push_back(light(scene, LightType::Directional, {0, 0, 0}, normalize(Vec3f(-0.5f, -1.0f, -0.1f)), Vec3f(0.5f)));
        }
        if (lighting == 2) scene.environment = std::make_shared<const EnvironmentLight>(EnvironmentLight::uniform(Vec3f(0.3f)));
        const Rig rig(scene);
        DirectLight direct(8, 7);
        direct.computeAll(scene, rig.bvh, rig.starts);
        const Bounds3f sceneBounds = scene.bounds();
        const Vec3f lower = sceneBounds.lower, extent = sceneBounds.upper - sceneBounds.lower;
        uint64_t state = 11;
        auto uniform = [&] {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            return float(state >> 40) / float(1u << 24);
        };
        for (const float size : {0.1f, 0.5f, 2.0f}) {
            for (int k = 0; k < 6; ++k) {
                const Vec3f centre = lower + Vec3f(uniform() * extent.x, uniform() * extent.y, uniform() * extent.z);
                Bounds3f box;
                box.extend(centre - Vec3f(0.5f * size));
                box.extend(centre + Vec3f(0.5f * size));
                uint64_t culledDerived = 0, allDerived = 0;
                const std::vector<uint32_t> culled =
                    direct.raysMeeting(scene, rig.starts, {box}, DirectLight::ShadowCull::ByCone, &culledDerived);
                const std::vector<uint32_t> all = direct.raysMeeting(scene, rig.starts, {box}, DirectLight::ShadowCull::None, &allDerived);
                EXPECT_EQ(culled, all) << "a " << size << " m box at " << centre.x << ", " << centre.y << ", " << centre.z;
                EXPECT_EQ(allDerived, scene.vertexCount());
                EXPECT_GE(culledDerived, all.size());
                if (lighting == 0 && size == 0.1f) {
                    EXPECT_LT(double(culledDerived), 0.5 * double(scene.vertexCount())) << "a 10 cm box at " << centre.x << ", " << centre.y;
                }
            }
        }
    }
}
