// After the first bounce only (EstimatorContext::afterFirstBounce, for --direct exact: direct
// light is computed apart by shadow rays, so the estimators count only what arrives after at least
// one bounce). Every estimator leaves the segments of bounce 0 out everywhere it reads segments:
// indexed equals brute force to the bit; the answer is exactly that of a cache holding only the
// segments of later bounces (fixed-point sums: E_all − E_after is bounce 0's alone); incremental
// frames equal a recomputation to the bit; and a plane under a point light, which nothing
// reflects light back to, receives exactly nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <functional>
#include <memory>
#include <ostream>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "estimate/detp.h"
#include "estimate/estimator.h"
#include "pipeline/frame_solver.h"
#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "test_support.h"
#include "trace/envelope.h"
#include "trace/photon_tracer.h"
#include "trace/tracked_paths.h"

using namespace qsgi;

namespace {

// A solve's radiosity, its record kept in `record` for the checks that read it.
const VertexRadiosity& recorded(FrameTiming& record, FrameSolver::Solution solved) {
    record = std::move(solved.record);
    return solved.radiosity;
}


bool sameBits(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Vec3f)) == 0;
}

size_t firstDifference(const std::vector<Vec3f>& a, const std::vector<Vec3f>& b) {
    for (size_t i = 0; i < std::min(a.size(), b.size()); ++i)
        if (std::memcmp(&a[i], &b[i], sizeof(Vec3f)) != 0) return i;
    return std::min(a.size(), b.size());
}

float largestComponent(const std::vector<Vec3f>& values) {
    float m = 0;
    for (const Vec3f& v : values) m = std::max(m, maxComponent(v));
    return m;
}

// Impact count, the photon map with k = 30, DETP clip and linear: the estimators the PLY pins
// (ply_pin_test.cpp) cover.
struct Case {
    std::string name;
    EstimatorKind kind;
    DetpBoundary rule;
    bool index = true;
    EstimatorSettings settings(float radius) const {
        EstimatorSettings s;
        s.kind = kind;
        s.detp.boundary = rule;
        s.radius = radius;
        s.photonMap.k = 30;
        s.useIndex = index;
        return s;
    }
};

// gtest names a failing parameter by this.
void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

const Case kCases[] = {
    {"impact_count", EstimatorKind::ImpactCount, DetpBoundary::Clip},
    {"photon_map", EstimatorKind::PhotonMap, DetpBoundary::Clip},
    {"detp_clip", EstimatorKind::Detp, DetpBoundary::Clip},
    {"detp_linear", EstimatorKind::Detp, DetpBoundary::Linear},
};

Scene litCornell() {
    Warnings w;
    return loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
}

Scene litBoxOnFloor() {
    Scene s = testscenes::boxOnFloor(24, 6, Vec3f(0.6f));
    testscenes::addPointLight(s, Vec3f(0.4f, 1.5f, 0.3f), Vec3f(10.0f));
    return s;
}

// The same cache without its segments of bounce 0, at the same power scale (the quantum of the
// fixed-point sums).
RayCache laterBounces(const RayCache& cache) {
    std::vector<Segment> later;
    cache.forEachSegment([&](const Segment& s) {
        if (s.bounce >= 1) later.push_back(s);
    });
    return RayCache::ofSegments(std::move(later), cache.maxPhotonPower);
}

// One scene's BVH and the disc regions of one radius, shared by the estimates compared.
struct Fixture {
    const Scene& scene;
    EmbreeDevice device;
    SceneBvh bvh;
    DiscRegions discs, covered;
    Fixture(const Scene& s, float radius) : scene(s), bvh(device, s), discs(radius, false), covered(radius, true) {
        discs.computeAll(scene, bvh);
        covered.computeAll(scene, bvh);
    }
    std::vector<Vec3f> estimate(const RayCache& cache, const EstimatorSettings& e, bool afterFirstBounce) {
        const DiscRegions* regions = e.kind == EstimatorKind::PhotonMap ? &covered : &discs;
        return estimateVertexRadiosity(scene, bvh, cache, e, device, regions, afterFirstBounce).irradiance;
    }
};

// A scene with its animation, ready to be posed frame by frame (as RenderJob prepares it).
struct Animated {
    Scene scene;
    std::function<Pose(int)> poseAt;
};

Animated animatedCornell() {
    const std::string dir = (sourceDir() / "data/cornell").string();
    Animated a{litCornell(), {}};
    const Animation animation = Animation::fromTransformFile(dir + "/animation.json", a.scene);
    a.scene.setRestPose(animation.poseAt(0));
    a.scene.markDynamic(animation.movedNodes(), animation.morphedNodes());
    sweepAnimationBounds(a.scene, animation);
    a.poseAt = [animation](int f) { return animation.poseAt(f); };
    return a;
}

// The box-on-floor scene of incremental_test.cpp: the cube slides through the light, casting a
// shadow on the floor and lit itself.
Animated slidingCube(int frames) {
    Animated a{testscenes::boxOnFloor(16, 3, Vec3f(0.7f)), {}};
    testscenes::addPointLight(a.scene, Vec3f(0.4f, 2.0f, 0.3f), Vec3f(20.0f));
    int cube = -1;
    for (size_t i = 0; i < a.scene.nodes.size(); ++i)
        if (a.scene.nodes[i].name == "Cube") cube = int(i);
    const std::vector<Transform> rest = a.scene.restLocals();
    a.poseAt = [rest, cube](int f) {
        std::vector<Transform> locals = rest;
        locals[size_t(cube)] = Transform::fromTRS(Vec3d(0.11 * f, 0, 0.05 * f), {0, 0, 0, 1}, Vec3d(1.0)) * locals[size_t(cube)];
        return Pose(locals);
    };
    a.scene.markDynamic({cube});
    sweepAnimationBounds(a.scene, frames - 1, a.poseAt);
    return a;
}

// Frames [0, frames) updated incrementally against the same frames with --full-recompute, both
// under exact direct light without a gather, where E = D + I and I is the estimator's answer after
// the first bounce: D is the same function of the pose in both, so equal bits for E mean equal
// bits for I. Every frame's irradiance and radiosity have the same bits.
void expectIncrementalEqualsFull(const std::function<Animated()>& make, const Case& c, float radius, uint64_t photons,
                                 int frames) {
    SCOPED_TRACE(c.name + (c.index ? "" : " brute force"));
    Animated inc = make(), full = make();
    EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator = c.settings(radius);
    s.trace.photons = photons;
    s.trace.seed = 3;
    s.lighting.direct = DirectLighting::Exact;
    s.lighting.directSamples = 4;
    s.lighting.gatherRays = 0;
    s.update.alwaysUpdate = true;  // the update, however large the change
    FrameSolverSettings r = s;
    r.update.fullRecompute = true;
    FrameSolver incremental(inc.scene, device, s), reference(full.scene, device, r);
    uint64_t retraced = 0;
    for (int f = 0; f < frames; ++f) {
        FrameTiming ti, tf;
        const VertexRadiosity& ri = recorded(ti, incremental.solve(inc.poseAt(f)));
        const VertexRadiosity& rf = recorded(tf, reference.solve(full.poseAt(f)));
        ASSERT_TRUE(sameBits(ri.irradiance, rf.irradiance))
            << "frame " << f << ": first differing vertex " << firstDifference(ri.irradiance, rf.irradiance);
        ASSERT_TRUE(sameBits(ri.radiosity, rf.radiosity)) << "frame " << f;
        if (f == 0) {
            EXPECT_GT(largestComponent(rf.irradiance), 0.0f);
        } else {
            EXPECT_FALSE(ti.fromScratch) << "frame " << f;
            retraced += ti.pathsRetraced;
        }
    }
    // The mover stands in the light: the updates retraced paths from their emission on, so they
    // met segments of bounce 0 to leave out and later ones to count.
    EXPECT_GT(retraced, 0u);
}

}  // namespace

// Brute force (useIndex = false: every vertex against every segment) counts the same segments as
// the indexes, so with fixed-point sums (DETP, impact count) and the same k nearest (the photon
// map) the answers have the same bits, with and without (a control, at one radius) the segments of
// bounce 0. DETP's free reference, detpBruteForce, agrees too. Radii below and above the vertex
// spacing (Cornell: 3 cm; the floor: 17 cm).
TEST(AfterFirstBounce, IndexedEqualsBruteForceToTheBit) {
    const uint64_t photons = kSanitized ? 1000 : 3000;
    using Radii = std::vector<float>;
    for (const auto& [name, scene, radii] : {std::tuple{std::string("cornell"), litCornell(), Radii{0.05f}},
                                             std::tuple{std::string("box on floor"), litBoxOnFloor(), Radii{0.02f, 0.3f}}}) {
        const RayCache cache = traceScene(scene, photons, 11);
        for (const float radius : radii) {
            Fixture fixture(scene, radius);
            for (const Case& c : kCases) {
                SCOPED_TRACE(name + ", r = " + std::to_string(radius) + ", " + c.name);
                EstimatorSettings e = c.settings(radius);
                for (const bool after : {true, false}) {
                    if (!after && radius != radii.front()) continue;
                    e.useIndex = false;
                    const std::vector<Vec3f> brute = fixture.estimate(cache, e, after);
                    e.useIndex = true;
                    e.sortQueries = true;
                    const std::vector<Vec3f> sorted = fixture.estimate(cache, e, after);
                    e.sortQueries = false;
                    const std::vector<Vec3f> unsorted = fixture.estimate(cache, e, after);
                    EXPECT_TRUE(sameBits(sorted, brute)) << "after first bounce " << after << ": first differing vertex "
                                                         << firstDifference(sorted, brute);
                    EXPECT_TRUE(sameBits(unsorted, brute)) << "after first bounce " << after << ", unsorted";
                    EXPECT_GT(largestComponent(brute), 0.0f) << "after first bounce " << after;
                    if (c.kind == EstimatorKind::Detp && after) {
                        EXPECT_TRUE(sameBits(detpBruteForce(scene, cache, radius, c.rule, &fixture.discs, &fixture.bvh, true),
                                             brute));
                    }
                }
            }
        }
    }
}

// Fixed-point sums make E_all − E_after exactly bounce 0's share: with afterFirstBounce every
// estimator answers, to the bit, what it answers without the flag on a cache of the same photons
// holding only their segments of bounce ≥ 1 (the same power quantum). The photon map too: its
// index then holds exactly those impacts, with the same (path, bounce) keys for ties. DETP's
// FLANN candidates likewise (its impact index holds the later impacts only).
TEST(AfterFirstBounce, EqualsTheSameEstimateOverTheLaterBouncesAlone) {
    const Scene scene = litCornell();
    const RayCache cache = traceScene(scene, kSanitized ? 10000 : 100000, 5);
    const RayCache later = laterBounces(cache);
    ASSERT_GT(later.segmentCount(), 0u);
    ASSERT_LT(later.segmentCount(), cache.segmentCount());
    const float radius = 0.05f;
    Fixture fixture(scene, radius);
    for (const Case& c : kCases) {
        SCOPED_TRACE(c.name);
        const EstimatorSettings e = c.settings(radius);
        const std::vector<Vec3f> after = fixture.estimate(cache, e, true);
        const std::vector<Vec3f> alone = fixture.estimate(later, e, false);
        EXPECT_TRUE(sameBits(after, alone)) << "first differing vertex " << firstDifference(after, alone);
        EXPECT_GT(largestComponent(after), 0.0f);
        // Direct light is most of what the walls receive: leaving it out changes the answer.
        EXPECT_FALSE(sameBits(after, fixture.estimate(cache, e, false)));
        if (c.kind == EstimatorKind::Detp) {
            EstimatorSettings flann = e;
            flann.detp.index = DetpIndex::Flann;
            EXPECT_TRUE(sameBits(fixture.estimate(cache, flann, true), fixture.estimate(later, flann, false))) << "flann";
        }
    }
}

// Every estimator's update leaves bounce 0 out as its solve does: the removed and added tails of
// retraced paths (which include emission segments: the cube stands in the light) and, for the
// photon map, the neighbour lists and ballsHolding; for DETP the remembered crossings. Three
// frames of data/cornell's animation at 10^5 photons.
class AfterFirstBounceOnCornell : public ::testing::TestWithParam<Case> {};

TEST_P(AfterFirstBounceOnCornell, IncrementalFramesEqualFullRecomputation) {
    expectIncrementalEqualsFull(animatedCornell, GetParam(), 0.05f, kSanitized ? 10000 : 100000, 3);
}

INSTANTIATE_TEST_SUITE_P(Estimators, AfterFirstBounceOnCornell, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return info.param.name; });

// The other updates on a small scene: brute force (every changed segment against every vertex)
// and the published rules, which the Cornell cases do not run.
TEST(AfterFirstBounce, BruteForceAndPaperRuleUpdatesEqualFullRecomputation) {
    const int frames = 4;
    const auto make = [frames] { return slidingCube(frames); };
    const Case cases[] = {
        {"photon map brute force", EstimatorKind::PhotonMap, DetpBoundary::Clip, false},
        {"detp clip brute force", EstimatorKind::Detp, DetpBoundary::Clip, false},
        {"detp linear brute force", EstimatorKind::Detp, DetpBoundary::Linear, false},
        {"photon map paper", EstimatorKind::PhotonMap, DetpBoundary::Paper},
        {"detp paper", EstimatorKind::Detp, DetpBoundary::Paper},
    };
    for (const Case& c : cases) {
        expectIncrementalEqualsFull(make, c, 0.12f, c.index ? 6000 : 1500, frames);
        if (HasFatalFailure()) return;
    }
}

// A plane under a point light and nothing else (tests/scenes/plane_point_light.gltf): every photon
// that lands, lands on the plane first, and what the plane reflects leaves the scene. After the
// first bounce there is no light at all: every vertex's irradiance is exactly 0, for every
// estimator, indexed and brute force, while the photons' own estimate is not.
TEST(AfterFirstBounce, APlaneUnderAPointLightReceivesNothingAfterTheFirstBounce) {
    Warnings w;
    const Scene scene = loadGltfScene((sourceDir() / "tests/scenes/plane_point_light.gltf").string(), w);
    const float radius = 0.05f;
    Fixture fixture(scene, radius);
    for (const uint64_t photons : {uint64_t(kSanitized ? 10000 : 100000), uint64_t(1000)}) {
        const RayCache cache = traceScene(scene, photons, 3);
        // The premise: the plane reflects (bounce-1 segments exist), and nothing comes back.
        uint64_t reflected = 0, landedAgain = 0;
        cache.forEachSegment([&](const Segment& s) {
            reflected += s.bounce >= 1;
            landedAgain += s.bounce >= 1 && s.hasImpact();
        });
        ASSERT_GT(reflected, 0u);
        ASSERT_EQ(landedAgain, 0u);
        // Brute force on the small cache only (vertices × segments).
        const bool index = photons > 1000;
        for (const Case& c : kCases) {
            SCOPED_TRACE(c.name + (index ? "" : " brute force"));
            EstimatorSettings e = c.settings(radius);
            e.useIndex = index;
            const std::vector<Vec3f> after = fixture.estimate(cache, e, true);
            ASSERT_EQ(after.size(), scene.vertexCount());
            EXPECT_TRUE(sameBits(after, std::vector<Vec3f>(scene.vertexCount(), Vec3f(0.0f))))
                << "largest component " << largestComponent(after);
            EXPECT_GT(largestComponent(fixture.estimate(cache, e, false)), 0.0f);
        }
    }
}
