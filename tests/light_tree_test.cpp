// The light tree (lib/trace/light_tree.h) and direct light sampled through it (issue 58): the
// tree's choices are a probability distribution equal to the product along each path, its nodes
// bound their children, every emitter that can light a point may be chosen there; the sampled
// direct light is unbiased against the exhaustive sum on a scene of many lights and occluders; one
// light or one emissive triangle gives what direct light gave before the tree, to the bit.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "estimate/direct_light.h"
#include "estimate/vertex_samples.h"
#include "scene/emission_pieces.h"
#include "test_support.h"
#include "trace/light_sampler.h"
#include "trace/light_tree.h"
#include "trace/sampling.h"
#include "trace/scene_bvh.h"

using namespace qsgi;

namespace {

struct Emitters {
    std::vector<LightBounds> bounds;
    // What each is, to tell whether it can light a point: a triangle's corners and normal, a
    // light's position (a spot's axis and cone in `normal`, `cosOuter`).
    struct Shape {
        enum Kind { Triangle, Point, Spot } kind;
        Vec3f corner[3];
        Vec3d normal;
        double cosOuter = -1;
    };
    std::vector<Shape> shapes;
};

// `count` emitters of mixed kinds at random in a 10 m cube, clustered in a few groups (as lamps
// are), with some of zero power.
Emitters randomEmitters(size_t count, uint64_t seed) {
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    auto direction = [&] {
        const double z = 2 * unit(random) - 1, phi = 2 * M_PI * unit(random), r = std::sqrt(1 - z * z);
        return Vec3d(r * std::cos(phi), r * std::sin(phi), z);
    };
    std::vector<Vec3d> groups;
    for (int g = 0; g < 5; ++g) groups.push_back(Vec3d(10 * unit(random) - 5, 10 * unit(random) - 5, 10 * unit(random) - 5));
    Emitters e;
    for (size_t i = 0; i < count; ++i) {
        const Vec3d at = groups[size_t(random() % groups.size())] + direction() * (2 * unit(random));
        const double phi = i % 17 == 5 ? 0.0 : std::exp(4 * unit(random));
        Emitters::Shape s{};
        switch (random() % 3) {
            case 0: {
                s.kind = Emitters::Shape::Triangle;
                const double size = 0.02 + 0.5 * unit(random);
                for (auto& c : s.corner) c = Vec3f(at + direction() * size);
                const Vec3d n = cross(Vec3d(s.corner[1]) - Vec3d(s.corner[0]), Vec3d(s.corner[2]) - Vec3d(s.corner[0]));
                s.normal = normalize(n);
                e.bounds.push_back(LightBounds::triangle(s.corner, s.normal, phi));
                break;
            }
            case 1:
                s.kind = Emitters::Shape::Point;
                s.corner[0] = Vec3f(at);
                e.bounds.push_back(LightBounds::point(s.corner[0], phi));
                break;
            default:
                s.kind = Emitters::Shape::Spot;
                s.corner[0] = Vec3f(at);
                s.normal = direction();
                s.cosOuter = std::cos(0.05 + 1.5 * unit(random));
                e.bounds.push_back(LightBounds::spot(s.corner[0], s.normal, s.cosOuter, phi));
        }
        e.shapes.push_back(s);
    }
    return e;
}

// Whether emitter `s` sends (p, n) something: a triangle from some point of a fine grid of its
// points (its front toward p, in front of n), a light from in front of n (a spot's, in its cone).
bool canLight(const Emitters::Shape& s, const Vec3d& p, const Vec3d& n) {
    if (s.kind != Emitters::Shape::Triangle) {
        const Vec3d w = Vec3d(s.corner[0]) - p;
        if (!(dot(n, w) > 0)) return false;
        return s.kind == Emitters::Shape::Point || dot(-normalize(w), s.normal) >= s.cosOuter;
    }
    constexpr int kSteps = 24;
    for (int i = 0; i <= kSteps; ++i)
        for (int j = 0; i + j <= kSteps; ++j) {
            const double b1 = double(i) / kSteps, b2 = double(j) / kSteps;
            const Vec3d x = Vec3d(s.corner[0]) * (1 - b1 - b2) + Vec3d(s.corner[1]) * b1 + Vec3d(s.corner[2]) * b2;
            const Vec3d w = x - p;
            if (dot(n, w) > 0 && dot(s.normal, w) < 0) return true;
        }
    return false;
}

double angleBetween(const Vec3d& a, const Vec3d& b) { return std::acos(std::clamp(dot(a, b), -1.0, 1.0)); }

}  // namespace

// For random trees of mixed emitters and random points: sample()'s choice of u partitions [0, 1)
// into one interval per emitter and one for a descent that ends at a node whose two children are
// both bounded to nothing there (an outcome that brings no light, as in pbrt-v4; it can only
// happen where the emitters below cannot light the point). A fine grid of u finds each interval's
// length within two grid steps: the emitters' probabilities (probability(), the product along the
// path from the leaf up) and the failed descents' share sum to one, and the probability sample()
// reports for its choice is that product to a few roundings.
TEST(LightTree, SelectionProbabilitiesSumToOneAndEqualTheProductAlongEachPath) {
    size_t points = 0, withFailures = 0;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Emitters e = randomEmitters(seed == 1 ? 3 : 300, seed);
        const LightTree tree(e.bounds);
        ASSERT_FALSE(tree.empty());
        std::mt19937_64 random(seed * 977);
        std::uniform_real_distribution<double> unit(-6.0, 6.0);
        for (int k = 0; k < 20; ++k) {
            const Vec3d p(unit(random), unit(random), unit(random));
            const Vec3d n = normalize(Vec3d(unit(random), unit(random), unit(random)));
            double sum = 0;
            for (uint32_t i = 0; i < e.bounds.size(); ++i) {
                const double probability = tree.probability(p, n, i);
                ASSERT_GE(probability, 0.0);
                if (!(e.bounds[i].phi > 0)) {
                    EXPECT_EQ(probability, 0.0) << "an emitter of no power is never chosen";
                }
                sum += probability;
            }
            ASSERT_LE(sum, 1 + 1e-12);
            constexpr int kGrid = 1 << 14;
            std::vector<int> drawn(e.bounds.size(), 0);
            int failed = 0, failedRuns = 0;  // runs: the failed descents' intervals the grid sees
            LightTree::Choice choice;
            bool failing = false;
            for (int g = 0; g < kGrid; ++g) {
                const bool ok = tree.sample(p, n, (g + 0.5) / kGrid, choice);
                failedRuns += !ok && !failing;
                failing = !ok;
                if (!ok) {
                    ++failed;
                    continue;
                }
                if (drawn[choice.emitter]++ == 0) {
                    const double product = tree.probability(p, n, choice.emitter);
                    ASSERT_NEAR(choice.probability, product, 1e-12 * product) << "emitter " << choice.emitter;
                }
            }
            for (uint32_t i = 0; i < e.bounds.size(); ++i)
                ASSERT_NEAR(double(drawn[i]) / kGrid, tree.probability(p, n, i), 2.0 / kGrid) << "emitter " << i;
            // Each interval the grid finds is within two steps of its length.
            EXPECT_NEAR(sum + double(failed) / kGrid, 1.0, 2.0 * (failedRuns + 1) / kGrid) << "seed " << seed << ", point " << k;
            ++points;
            withFailures += failed > 0;
        }
    }
    std::printf("%zu points, %zu with some failed descents\n", points, withFailures);
}

// Each interior node's bounds hold its children's: the box contains theirs, its power is their
// sum, its cone of normals contains their cones (angle between axes + child's half-angle within
// the node's, to the union's slack), and its θe is no narrower.
TEST(LightTree, EveryNodeBoundsItsChildren) {
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        const Emitters e = randomEmitters(500, seed + 10);
        const LightTree tree(e.bounds);
        size_t inLeaves = 0;
        for (size_t i = 0; i < tree.nodeCount(); ++i) {
            const LightTree::Node& node = tree.node(i);
            bool underPanel = false;  // a panel's nodes are never descended into: their ranges are stale
            for (int32_t up = node.parent; up >= 0; up = tree.node(size_t(up)).parent) underPanel = underPanel || tree.node(size_t(up)).panel;
            if (node.leaf() && !underPanel) {
                // A leaf bounds its emitters as a node its children.
                EXPECT_EQ(node.count, 1u) << "a leaf holds one emitter";
                double phi = 0;
                for (uint32_t k = 0; k < node.count; ++k) {
                    const LightBounds& b = e.bounds[tree.leafEmitter(node, k)];
                    EXPECT_TRUE(node.bounds.box.contains(b.box.lower) && node.bounds.box.contains(b.box.upper)) << "leaf " << i;
                    EXPECT_LE(node.bounds.cosTheta_e, b.cosTheta_e);
                    if (node.bounds.cosTheta_o > -1) {
                        EXPECT_LE(angleBetween(node.bounds.axis, b.axis) + std::acos(b.cosTheta_o), std::acos(node.bounds.cosTheta_o) + 1e-6);
                    }
                    phi += b.phi;
                }
                EXPECT_NEAR(node.bounds.phi, phi, 1e-12 * phi);
                inLeaves += node.count;
                continue;
            }
            if (node.leaf()) {
                ++inLeaves;
                continue;
            }
            const LightBounds& b = node.bounds;
            double phi = 0;
            for (const size_t c : {i + 1, size_t(node.second)}) {
                const LightBounds& child = tree.node(c).bounds;
                EXPECT_EQ(tree.node(c).parent, int32_t(i));
                EXPECT_TRUE(b.box.contains(child.box.lower) && b.box.contains(child.box.upper)) << "node " << i;
                phi += child.phi;
                EXPECT_LE(b.cosTheta_e, child.cosTheta_e);
                if (b.cosTheta_o > -1) {
                    EXPECT_LE(angleBetween(b.axis, child.axis) + std::acos(child.cosTheta_o), std::acos(b.cosTheta_o) + 1e-6)
                        << "node " << i << "'s cone holds child " << c << "'s";
                }
            }
            EXPECT_NEAR(b.phi, phi, 1e-12 * phi);
        }
        size_t powered = 0;
        for (const LightBounds& l : e.bounds) powered += l.phi > 0;
        EXPECT_EQ(inLeaves, powered) << "every emitter of some power in one leaf";
    }
}

// Conservative: at random points and normals, every emitter that can send the point light (found
// by the emitter's own geometry, not the tree's bounds) has a probability above 0 there.
TEST(LightTree, EveryEmitterThatCanLightAPointHasAProbabilityAboveZero) {
    size_t checked = 0, unlit = 0;
    for (uint64_t seed = 1; seed <= 3; ++seed) {
        const Emitters e = randomEmitters(400, seed + 20);
        const LightTree tree(e.bounds);
        std::mt19937_64 random(seed);
        std::uniform_real_distribution<double> unit(-6.0, 6.0);
        for (int k = 0; k < 40; ++k) {
            const Vec3d p(unit(random), unit(random), unit(random));
            const Vec3d n = normalize(Vec3d(unit(random), unit(random), unit(random)));
            for (uint32_t i = 0; i < e.bounds.size(); ++i) {
                if (!(e.bounds[i].phi > 0)) continue;
                if (!canLight(e.shapes[i], p, n)) {
                    ++unlit;
                    continue;
                }
                ++checked;
                ASSERT_GT(tree.probability(p, n, i), 0.0) << "seed " << seed << ", point " << k << ", emitter " << i;
            }
        }
    }
    std::printf("%zu (point, emitter) pairs that can light checked, %zu that cannot\n", checked, unlit);
    EXPECT_GT(checked, 10000u);
    EXPECT_GT(unlit, 10000u);
}

// Unbiased (issue 58): on a floor with three blocks under 60 small lamps and 120 point and spot
// lights (some under the floor), direct light at S = 16 — so the lights join the lamps in the tree
// — averaged over 64 seeds equals the exhaustive sum at every vertex within its standard error.
// The exhaustive sum is independent of the tree: each light's exact shadow ray (DirectLight with S
// above the light count, the lamps dark) plus the lamps by area sampling at 4096 points a vertex,
// uniform over their total area (its own standard error included). z = (mean − exhaustive) /
// √(SE_mean² + SE_exhaustive²) is then close to standard normal: the mean of z² within
// 1 ± 0.25 (its spread is √(2 / vertices) ≈ 0.05, the rest for the standard errors' own noise),
// and no |z| above 5.5.
TEST(ManyLights, SampledDirectLightIsUnbiasedAgainstTheExhaustiveSum) {
    const Scene scene = testscenes::lampsOverBlocks(14, 60, 120, 5);
    const SecondPassRig rig(scene);
    const uint32_t vertices = uint32_t(scene.vertexCount());
    ASSERT_TRUE(DirectLight::samplesLights(120, 16));

    // The lights, exactly: S above their count, and the lamps left out (a copy with them dark).
    Scene lightsOnly = scene;
    for (Material& m : lightsOnly.materials) m.emission = Vec3f(0.0f);
    DirectLight exactLights(128, 1);
    exactLights.computeAll(lightsOnly, rig.bvh, rig.starts);

    // The lamps: uniform over their total area, 4096 points a vertex.
    std::vector<uint32_t> lampTriangles;
    std::vector<double> cumulativeArea;
    double totalArea = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t)
        if (scene.materials[scene.triangleMaterial[t]].isEmissive()) {
            lampTriangles.push_back(t);
            totalArea += double(scene.triangleArea(t));
            cumulativeArea.push_back(totalArea);
        }
    ASSERT_EQ(lampTriangles.size(), 120u);
    std::vector<Vec3d> exhaustive(vertices), exhaustiveVariance(vertices);
    std::mt19937_64 random(99);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    constexpr int kPoints = 4096;
    for (uint32_t v = 0; v < vertices; ++v) {
        const Vec3d p(scene.positions[v]), n(rig.starts.normal(v));
        const Vec3f origin = rig.starts.point(v);
        Vec3d sum(0.0), sumSquares(0.0);
        for (int i = 0; i < kPoints; ++i) {
            const double pick = unit(random) * totalArea;
            const size_t k = std::min(size_t(std::upper_bound(cumulativeArea.begin(), cumulativeArea.end(), pick) - cumulativeArea.begin()),
                                      lampTriangles.size() - 1);
            const uint32_t t = lampTriangles[k];
            float b1, b2;
            uniformTriangle(float(unit(random)), float(unit(random)), b1, b2);
            const Triangle& tri = scene.triangles[t];
            const Vec3d x = Vec3d(scene.positions[tri.v[0]]) * double(1 - b1 - b2) + Vec3d(scene.positions[tri.v[1]]) * double(b1) +
                            Vec3d(scene.positions[tri.v[2]]) * double(b2);
            const Vec3d d = x - p;
            const double d2 = dot(d, d), dist = std::sqrt(d2);
            const Vec3d w = d / dist;
            const double cosV = dot(n, w), cosE = -dot(Vec3d(scene.geometricNormal(t)), w);
            Vec3d value(0.0);
            if (cosV > 0 && cosE > 0) {
                const Vec3d s = x - Vec3d(origin);
                const float len = float(length(s));
                const float end = len * (1 - 1e-5f) - rig.bvh.rayEpsilon();
                if (!(end > 0) || !rig.bvh.occluded(origin, Vec3f(s / length(s)), 0.0f, end))
                    value = Vec3d(scene.materials[scene.triangleMaterial[t]].emission) * (cosV * cosE / d2 * totalArea);
            }
            sum += value;
            sumSquares += value * value;
        }
        const Vec3d mean = sum / double(kPoints);
        exhaustive[v] = mean + Vec3d(exactLights.irradiance()[v]);
        exhaustiveVariance[v] = (sumSquares / double(kPoints) - mean * mean) / double(kPoints - 1);
    }

    constexpr int kSeeds = 64;
    std::vector<Vec3d> sum(vertices, Vec3d(0.0)), sumSquares(vertices, Vec3d(0.0));
    for (int seed = 1; seed <= kSeeds; ++seed) {
        DirectLight sampled(16, uint64_t(seed));
        sampled.computeAll(scene, rig.bvh, rig.starts);
        ASSERT_EQ(sampled.sampledEmitters(), 240u) << "the lamps' 120 triangles and the 120 lights";
        for (uint32_t v = 0; v < vertices; ++v) {
            const Vec3d x(sampled.irradiance()[v]);
            sum[v] += x;
            sumSquares[v] += x * x;
        }
    }
    double sumZ2 = 0, largest = 0;
    size_t counted = 0;
    // Per channel, every vertex with light.
    for (uint32_t v = 0; v < vertices; ++v)
        for (int c = 0; c < 3; ++c) {
            const double mean = sum[v][c] / kSeeds;
            const double variance = (sumSquares[v][c] / kSeeds - mean * mean) * kSeeds / (kSeeds - 1);
            const double se2 = variance / kSeeds + exhaustiveVariance[v][c];
            if (!(exhaustive[v][c] > 0) && mean == 0) continue;
            ASSERT_GT(se2, 0.0) << "vertex " << v << " has light and no noise";
            const double z = (mean - exhaustive[v][c]) / std::sqrt(se2);
            if (std::abs(z) > 4)
                std::printf("v %u c %d at (%.2f %.2f %.2f) n (%.2f %.2f %.2f): mean %.5g exhaustive %.5g (lights %.5g) se %.3g seRef %.3g\n", v, c,
                            scene.positions[v].x, scene.positions[v].y, scene.positions[v].z, rig.starts.normal(v).x,
                            rig.starts.normal(v).y, rig.starts.normal(v).z, mean, exhaustive[v][c], exactLights.irradiance()[v][c],
                            std::sqrt(variance / kSeeds), std::sqrt(exhaustiveVariance[v][c]));
            sumZ2 += z * z;
            largest = std::max(largest, std::abs(z));
            ++counted;
        }
    const double meanZ2 = sumZ2 / double(counted);
    std::printf("%zu vertex channels with light: mean z^2 %.3f, largest |z| %.2f\n", counted, meanZ2, largest);
    EXPECT_GT(counted, 1000u);
    EXPECT_NEAR(meanZ2, 1.0, 0.25);
    EXPECT_LT(largest, 5.5);
}

// What the tree does not need to change, it does not (issue 58): one emissive triangle's samples
// are its own, with probability 1 — the value before the tree, L_e cosθ_v cosθ_e A / (d² S) summed
// over the vertex's Sobol points in order, to the bit; one point light's ray is exact as before.
TEST(ManyLights, OneEmissiveTriangleOrOneLightGivesTheAnswerBeforeTheTreeToTheBit) {
    // One triangle: the floor under a lamp of two triangles, the lamp cut to its first.
    Scene scene = testscenes::floorUnderEmitter(12, Vec3f(0.1f, 0.8f, -0.1f), 0.2f, 0.15f, Vec3f(3, 2, 1), Vec3f(0.5f));
    uint32_t lamp = UINT32_MAX;
    for (uint32_t t = 0; t < scene.triangleCount() && lamp == UINT32_MAX; ++t)
        if (scene.materials[scene.triangleMaterial[t]].isEmissive()) lamp = t;
    ASSERT_NE(lamp, UINT32_MAX);
    // The lamp's second triangle given the floor's material: it emits nothing.
    for (uint32_t t = lamp + 1; t < scene.triangleCount(); ++t)
        if (scene.materials[scene.triangleMaterial[t]].isEmissive()) scene.triangleMaterial[t] = scene.triangleMaterial[0];
    const SecondPassRig rig(scene);
    constexpr uint32_t kSamples = 16;
    DirectLight direct(kSamples, 7);
    direct.computeAll(scene, rig.bvh, rig.starts);
    ASSERT_EQ(direct.sampledEmitters(), 1u);
    const Triangle& tri = scene.triangles[lamp];
    const Vec3d corner[3] = {Vec3d(scene.positions[tri.v[0]]), Vec3d(scene.positions[tri.v[1]]), Vec3d(scene.positions[tri.v[2]])};
    const Vec3d emitterNormal(scene.geometricNormal(lamp));
    const Vec3d radiance(emissionPieces(scene, lamp).at(0).radiance);
    const double area = double(scene.triangleArea(lamp));
    size_t lit = 0;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3d p(scene.positions[v]), n(rig.starts.normal(v));
        const VertexSamples numbers(7, v, VertexStream::Direct);
        Vec3d sum(0.0);
        for (uint32_t i = 0; i < kSamples; ++i) {
            float b1, b2;
            uniformTriangle(numbers.uniform(i, 1), numbers.uniform(i, 2), b1, b2);
            const Vec3d x = corner[0] * double(1 - b1 - b2) + corner[1] * double(b1) + corner[2] * double(b2);
            const Vec3d d = x - p;
            const double d2 = dot(d, d);
            const Vec3d w = d / std::sqrt(d2);
            const double cosV = dot(n, w), cosE = -dot(emitterNormal, w);
            if (!(cosV > 0) || !(cosE > 0)) continue;
            // The floor sees the lamp unoccluded: every ray is clear.
            sum += radiance * (cosV * cosE / d2 * area / 1.0 * (1.0 / double(kSamples)));
        }
        if (sum.y > 0) ++lit;
        ASSERT_EQ(direct.irradiance()[v], Vec3f(sum)) << "vertex " << v;
    }
    EXPECT_GT(lit, 100u);

    // One point light: its single exact ray, I cosθ / d², as DirectLight.PointLightOverPlane checks.
    Scene plane = testscenes::plane(1.0f, 12, Vec3f(0.5f));
    testscenes::addPointLight(plane, Vec3f(0.2f, 0.8f, -0.1f), Vec3f(3, 2, 1));
    const SecondPassRig planeRig(plane);
    DirectLight one(kSamples, 7);
    one.computeAll(plane, planeRig.bvh, planeRig.starts);
    EXPECT_EQ(one.sampledEmitters(), 0u) << "one light is given its ray, not sampled";
    EXPECT_EQ(one.raysCast(), plane.vertexCount());
}

// Extreme light counts (issue 58) render finitely, with set-up that does not grow with the count
// as a map per light did: a million point lights over a small floor — a third of them at one
// point, a tenth of no power — and 200 directional lights; with a 1024-triangle emitter besides.
// Photon emission aims none of them (each light's share of the photons is below a probe's rays),
// direct light samples them all through the tree and the directional lights by their irradiance,
// and every vertex's light is finite and, on the lit floor, above 0.
TEST(ManyLights, AMillionLightsCoincidentAndPowerlessOnesRenderFinitely) {
    Scene scene = testscenes::floorUnderEmitter(8, Vec3f(0.0f, 1.5f, 0.0f), 0.4f, 0.4f, Vec3f(2.0f), Vec3f(0.5f));
    std::mt19937_64 random(11);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    constexpr size_t kLights = 1000000;
    scene.lights.reserve(kLights + 200);
    for (size_t k = 0; k < kLights; ++k) {
        PunctualLight l;
        l.type = k % 7 == 3 ? LightType::Spot : LightType::Point;
        l.position = k % 3 == 0 ? Vec3f(0.1f, 0.7f, 0.2f) : Vec3f(2 * unit(random), 0.3f + unit(random) + 1.0f, 2 * unit(random));
        l.position = Vec3f(Vec3d(l.position) - scene.worldOrigin);
        l.intensity = k % 10 == 9 ? Vec3f(0.0f) : Vec3f(1e-4f);
        l.direction = Vec3f(0, -1, 0);
        l.cosOuterCone = 0.5f;
        scene.lights.push_back(l);
    }
    for (int k = 0; k < 200; ++k) {
        PunctualLight l;
        l.type = LightType::Directional;
        l.direction = normalize(Vec3f(unit(random), -1.0f, unit(random)));
        l.intensity = Vec3f(k % 4 == 0 ? 0.0f : 0.01f);
        scene.lights.push_back(l);
    }
    const SecondPassRig rig(scene);
    const LightSampler photons(scene, 100000, rig.bvh.rayEpsilon(), EmissionAim{true, 0.05f}, uint64_t(1), &rig.bvh);
    EXPECT_EQ(photons.aimedLights(), 0u) << "no light has 256 photons to aim";
    DirectLight direct(16, 3);
    direct.computeAll(scene, rig.bvh, rig.starts);
    EXPECT_TRUE(direct.lightsSampled());
    EXPECT_EQ(direct.sampledEmitters(), 2 + kLights - kLights / 10) << "the lamp's two triangles and every light with power";
    // S = 16 samples each for the tree and the directional lights: never a ray per light.
    EXPECT_LE(direct.raysCast(), uint64_t(scene.vertexCount()) * 32);
    size_t lit = 0;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        ASSERT_TRUE(isFinite(direct.irradiance()[v])) << "vertex " << v;
        lit += direct.irradiance()[v].y > 0;
    }
    EXPECT_GT(lit, scene.vertexCount() / 2);
    std::printf("a million lights: tree of %zu emitters, %.1f MiB, built in %.2f s\n", direct.sampledEmitters(),
                double(direct.treeBytes()) / (1 << 20), direct.treeSeconds());
}
