// glTF animation sampling (issue 11): the interpolation modes as glTF 2.0 defines them, against
// values worked out by hand from the keys, on synthetic tracks and on Khronos' InterpolationTest
// model; and glTF animations as a source of frames (Animation::fromGltf): frame range, which nodes
// move, static lights, conflicting animations.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>

#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "scene/keyframes.h"
#include "test_support.h"
#include "util/error.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

KeyframeTrack track(Interpolation mode, std::vector<double> times, std::vector<double> values, int components) {
    KeyframeTrack t;
    t.interpolation = mode;
    t.times = std::move(times);
    t.values = std::move(values);
    t.components = components;
    return t;
}

double sample1(const KeyframeTrack& t, double time) {
    double v = 0;
    t.sample(time, false, &v);
    return v;
}

std::array<double, 4> sampleRotation(const KeyframeTrack& t, double time) {
    std::array<double, 4> q{};
    t.sample(time, true, q.data());
    return q;
}

// Rotation by `degrees` about −Z, as the InterpolationTest keys are.
std::array<double, 4> aboutMinusZ(double degrees) {
    const double half = degrees * M_PI / 360;
    return {0, 0, -std::sin(half), std::cos(half)};
}

void expectRotation(const std::array<double, 4>& q, const std::array<double, 4>& expected, double tolerance) {
    // q and −q are the same rotation.
    const double sign = q[0] * expected[0] + q[1] * expected[1] + q[2] * expected[2] + q[3] * expected[3] < 0 ? -1 : 1;
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(sign * q[c], expected[c], tolerance) << "component " << c;
}

}  // namespace

TEST(Keyframes, StepHoldsEachKeyUntilTheNextAndClampsOutside) {
    const KeyframeTrack t = track(Interpolation::Step, {1, 2, 4}, {10, 20, 40}, 1);
    EXPECT_EQ(sample1(t, 0), 10);    // before the first key
    EXPECT_EQ(sample1(t, 1), 10);
    EXPECT_EQ(sample1(t, 1.999), 10);
    EXPECT_EQ(sample1(t, 2), 20);    // a key's own time takes its value
    EXPECT_EQ(sample1(t, 3.5), 20);
    EXPECT_EQ(sample1(t, 4), 40);
    EXPECT_EQ(sample1(t, 100), 40);  // after the last key
}

TEST(Keyframes, LinearInterpolatesComponentwiseAndClamps) {
    const KeyframeTrack t = track(Interpolation::Linear, {0, 2, 3}, {0, 10, -4, 8, 2, 2}, 2);
    double v[2];
    t.sample(0.5, false, v);  // a quarter of the way from (0, 10) to (−4, 8)
    EXPECT_DOUBLE_EQ(v[0], -1);
    EXPECT_DOUBLE_EQ(v[1], 9.5);
    t.sample(2.5, false, v);  // halfway from (−4, 8) to (2, 2)
    EXPECT_DOUBLE_EQ(v[0], -1);
    EXPECT_DOUBLE_EQ(v[1], 5);
    t.sample(-1, false, v);
    EXPECT_EQ(v[0], 0);
    t.sample(7, false, v);
    EXPECT_EQ(v[1], 2);
}

TEST(Keyframes, LinearRotationIsSphericalAlongTheShorterArc) {
    // 0° to 90° about −Z: halfway is 45°, a third of the way 30° (a chord would give neither).
    const auto a = aboutMinusZ(0), b = aboutMinusZ(90);
    const KeyframeTrack t = track(Interpolation::Linear, {0, 3}, {a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]}, 4);
    expectRotation(sampleRotation(t, 1.5), aboutMinusZ(45), 1e-12);
    expectRotation(sampleRotation(t, 1.0), aboutMinusZ(30), 1e-12);
    // The second key given as −q (the same rotation): still the 45° midpoint, not a 225° detour.
    const KeyframeTrack flipped =
        track(Interpolation::Linear, {0, 3}, {a[0], a[1], a[2], a[3], -b[0], -b[1], -b[2], -b[3]}, 4);
    expectRotation(sampleRotation(flipped, 1.5), aboutMinusZ(45), 1e-12);
}

TEST(Keyframes, CubicSplineIsTheHermiteCurveOfValuesAndTangentsScaledByTheInterval) {
    // Keys at t = 1 (value 0, out-tangent 6) and t = 3 (in-tangent 0, value 4): td = 2. At s = 1/2
    // the Hermite weights are h00 = h01 = 1/2, h10 = 1/8, h11 = −1/8, so
    // p = 0/2 + 2·6/8 + 4/2 − 2·0/8 = 3.5; at s = 1/4: h00 = 27/32, h10 = 9/64, h01 = 5/32,
    // h11 = −3/64, p = 2·6·9/64 + 4·5/32 = 1.6875 + 0.625 = 2.3125.
    const KeyframeTrack t = track(Interpolation::CubicSpline, {1, 3}, {99, 0, 6, 0, 4, 99}, 1);
    EXPECT_DOUBLE_EQ(sample1(t, 2), 3.5);
    EXPECT_DOUBLE_EQ(sample1(t, 1.5), 2.3125);
    EXPECT_EQ(sample1(t, 0), 0);  // clamps to the values, never to a tangent (99)
    EXPECT_EQ(sample1(t, 9), 4);
}

TEST(Keyframes, InterpolationTestModelMatchesHandWorkedValues) {
    const fs::path file = sharedDir() / "data/gltf-samples/models/InterpolationTest/glTF/InterpolationTest.gltf";
    if (!fs::exists(file)) GTEST_SKIP() << "../shared is absent: " << file;
    Warnings warnings;
    const Scene scene = loadGltfScene(file.string(), warnings);
    ASSERT_EQ(scene.animations.size(), 9u);
    // The file's key times are float32: 0.4166666567325592 is 10/24 rounded, and so on.
    const double t1 = 0.4166666567325592, t2 = 0.875;
    auto channel = [&](const std::string& animation) -> const AnimationChannel& {
        for (const KeyframeAnimation& a : scene.animations)
            if (a.name == animation) return a.channels.at(0);
        throw std::runtime_error("no animation " + animation);
    };
    double v[4];
    // "Step Scale": keys 1, 0.5, 1, 0.5, 1 from t = 1/24.
    const KeyframeTrack& stepScale = channel("Step Scale").track;
    EXPECT_EQ(stepScale.interpolation, Interpolation::Step);
    stepScale.sample(0, false, v);
    EXPECT_EQ(v[0], 1.0);  // before the first key (t = 1/24)
    stepScale.sample(0.5, false, v);
    EXPECT_EQ(v[0], 0.5);
    stepScale.sample(1.3, false, v);
    EXPECT_EQ(v[0], 0.5);
    stepScale.sample(5, false, v);
    EXPECT_EQ(v[0], 1.0);
    // "Linear Scale": halfway between 0.5 (t1) and 1 (t2) is 0.75.
    channel("Linear Scale").track.sample((t1 + t2) / 2, false, v);
    EXPECT_NEAR(v[1], 0.75, 1e-12);
    // "CubicSpline Scale": zero tangents, so p = h00·0.5 + h01·1: 0.75 at s = 1/2, and
    // 27/32·0.5 + 5/32·1 = 0.578125 at s = 1/4.
    channel("CubicSpline Scale").track.sample((t1 + t2) / 2, false, v);
    EXPECT_NEAR(v[2], 0.75, 1e-12);
    channel("CubicSpline Scale").track.sample(t1 + (t2 - t1) / 4, false, v);
    EXPECT_NEAR(v[0], 0.578125, 1e-12);
    // "Step Rotation": 0°, 45°, 90°, 135°, 180° about −Z at 0, t1, 0.875, 1.25, 1.708.
    expectRotation(sampleRotation(channel("Step Rotation").track, 0.5), aboutMinusZ(45), 1e-7);
    expectRotation(sampleRotation(channel("Step Rotation").track, 1.0), aboutMinusZ(90), 1e-7);
    // "Linear Rotation": halfway from 45° to 90° is 67.5°; from 135° to 180°, 157.5°.
    expectRotation(sampleRotation(channel("Linear Rotation").track, (t1 + t2) / 2), aboutMinusZ(67.5), 1e-7);
    expectRotation(sampleRotation(channel("Linear Rotation").track, (1.25 + 1.7083333730697632) / 2),
                   aboutMinusZ(157.5), 1e-7);
    // "CubicSpline Rotation": key 0 (0°, out-tangent b0 = identity) to key 1 (45°, in-tangent
    // a1 = (0, 0, −0.0478909, 0.9988527)). At s = 1/2, h00 = h01 = 1/2 and h10 = −h11 = 1/8, so
    // p = (q0 + q45)/2 + (t1/8)(b0 − a1), normalised: z = −0.1913417 + 0.0520833·0.0478909,
    // w = 0.9619398 + 0.0520833·0.0011473, i.e. (−0.1926306, 0.9812713), 22.21°: the tangents
    // pull it short of the 22.5° a spherical midpoint would give.
    {
        const double a1z = -0.04789090156555176, a1w = 0.9988526701927185;
        const auto q45 = aboutMinusZ(45);
        const double z = 0.5 * q45[2] + t1 / 8 * (0 - a1z), w = 0.5 * (1 + q45[3]) + t1 / 8 * (1 - a1w);
        const double norm = std::hypot(z, w);
        expectRotation(sampleRotation(channel("CubicSpline Rotation").track, t1 / 2), {0, 0, z / norm, w / norm}, 1e-7);
        EXPECT_NEAR(z / norm, -0.1926306, 1e-6);
    }
    // "Step Translation": y = 6.665, 10, 6, 10, 6 at 0, 0.458, 0.833, 1.292, 1.708.
    channel("Step Translation").track.sample(0.5, false, v);
    EXPECT_EQ(v[1], 10.0);
    // "Linear Translation": y from 10 (t1) to 6 (0.8333): at t = 0.5, s = 0.2, so y = 9.2.
    channel("Linear Translation").track.sample(0.5, false, v);
    EXPECT_NEAR(v[1], 9.2, 1e-6);
    EXPECT_NEAR(v[0], -3.2975807189941406, 1e-12);
    // "CubicSpline Translation": y from 10 to 6 with zero tangents: 8 at s = 1/2, 9.375 at s = 1/4.
    const double t8 = 0.8333333134651184;
    channel("CubicSpline Translation").track.sample((t1 + t8) / 2, false, v);
    EXPECT_NEAR(v[1], 8, 1e-12);
    channel("CubicSpline Translation").track.sample(t1 + (t8 - t1) / 4, false, v);
    EXPECT_NEAR(v[1], 9.375, 1e-12);
    // After the last key every channel holds its last value.
    channel("Linear Translation").track.sample(100, false, v);
    EXPECT_EQ(v[1], 6.0);
}

TEST(Keyframes, AnimatedTriangleTurnsAlongTheShorterArcThroughEveryQuarter) {
    // Khronos' AnimatedTriangle: one LINEAR rotation about +z, keys 0°, 90°, 180°, 270°, 360° at
    // t = 0, 0.25, 0.5, 0.75, 1 s, written as (0, 0, 0.707, 0.707), (0, 0, 1, 0), (0, 0, 0.707,
    // −0.707), (0, 0, 0, 1). Halfway between keys: 45°, 225° and 315° — the last key is the
    // negation of 360°'s quaternion as it follows 270°'s, so only the shorter arc gives 315°.
    // The file's 0.707 is not √½: expected values hold to 2e-4.
    const fs::path file = sharedDir() / "data/gltf-samples/models/AnimatedTriangle/glTF-Embedded/AnimatedTriangle.gltf";
    if (!fs::exists(file)) GTEST_SKIP() << "../shared is absent: " << file;
    Warnings warnings;
    const Scene scene = loadGltfScene(file.string(), warnings);
    ASSERT_EQ(scene.animations.size(), 1u);
    const KeyframeTrack& t = scene.animations[0].channels.at(0).track;
    auto aboutZ = [](double degrees) {
        const double half = degrees * M_PI / 360;
        return std::array<double, 4>{0, 0, std::sin(half), std::cos(half)};
    };
    expectRotation(sampleRotation(t, 0.125), aboutZ(45), 2e-4);
    expectRotation(sampleRotation(t, 0.625), aboutZ(225), 2e-4);
    expectRotation(sampleRotation(t, 0.875), aboutZ(315), 2e-4);
    // Via the animation at 8 fps: frame 1 is t = 0.125 s.
    const Animation a = Animation::fromGltf(scene, 0, 8, "test");
    EXPECT_EQ(a.lastFrame(), 8);
    const Vec3d x = a.localsAt(1)[0].applyVector(Vec3d(1, 0, 0));
    EXPECT_NEAR(x.x, std::sqrt(0.5), 2e-4);
    EXPECT_NEAR(x.y, std::sqrt(0.5), 2e-4);
}

TEST(Keyframes, GltfAnimationGivesFramesAtTheFrameRateThroughTheLastKey) {
    const fs::path file = sharedDir() / "data/gltf-samples/models/InterpolationTest/glTF/InterpolationTest.gltf";
    if (!fs::exists(file)) GTEST_SKIP() << "../shared is absent: " << file;
    Warnings warnings;
    Scene scene = loadGltfScene(file.string(), warnings);
    // All nine at once: they drive different nodes. The last key is at 1.7083333 s = 41/24 (as a
    // float, a hair above): 41 frames after frame 0 at 24 fps, 82 at 48.
    const Animation all = Animation::fromGltf(scene, -1, 24, "test");
    EXPECT_EQ(all.lastFrame(), 41);
    EXPECT_EQ(Animation::fromGltf(scene, -1, 48, "test").lastFrame(), 82);
    EXPECT_EQ(all.movedNodes().size(), 9u);
    // Frame 12 is t = 0.5 s: "Linear Translation" moves Cube.009 to y = 9.2 (see above).
    int cube9 = -1;
    for (size_t n = 0; n < scene.nodes.size(); ++n)
        if (scene.nodes[n].name == "Cube.009") cube9 = int(n);
    ASSERT_GE(cube9, 0);
    const Vec3d p = all.localsAt(12)[size_t(cube9)].applyPoint(Vec3d(0.0));
    EXPECT_NEAR(p.y, 9.2, 1e-6);
    EXPECT_NEAR(p.x, -3.2975807189941406, 1e-12);
    // Past the last frame the pose holds.
    EXPECT_EQ(all.localsAt(41), all.localsAt(1000));
    // One animation alone (gltf:N), and one that does not exist.
    EXPECT_EQ(Animation::fromGltf(scene, 8, 24, "test").movedNodes(), std::vector<int>{cube9});
    try {
        Animation::fromGltf(scene, 9, 24, "scene.gltf (--animation gltf:9)");
        FAIL() << "animation 9 does not exist";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no glTF animation 9"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("8 'Linear Translation'"), std::string::npos) << e.what();
    }
}

namespace {

// A floor, a box on a node "Mover" and a point light on node "Lamp", with one animation per
// entry of `channels` (each {node, path, times, values}).
struct ChannelSpec {
    int node;
    std::string path;
    std::vector<float> times, values;
};

fs::path writeAnimatedScene(const std::string& name, const std::vector<std::vector<ChannelSpec>>& animations) {
    testscenes::GltfWriter w;
    const int positions = w.accessor({-1, 0, 1, 1, 0, 1, 1, 0, -1, -1, 0, -1}, "VEC3");
    const int indices = w.indices({0, 1, 2, 0, 2, 3});
    using nlohmann::json;
    w.doc["meshes"] = json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", positions}}}, {"indices", indices}}})}}});
    const int floor = w.node({{"name", "Floor"}, {"mesh", 0}});
    const int mover = w.node({{"name", "Mover"}, {"mesh", 0}, {"translation", {0, 1, 0}}, {"scale", {0.2, 0.2, 0.2}}});
    const int lamp = w.node({{"name", "Lamp"}, {"translation", {0, 3, 0}},
                             {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
    w.doc["scenes"] = json::array({{{"nodes", {floor, mover, lamp}}}});
    w.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    w.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", json::array({{{"type", "point"}, {"intensity", 10}}})}}}};
    for (const auto& channels : animations) {
        json animation = {{"channels", json::array()}, {"samplers", json::array()}};
        for (const ChannelSpec& c : channels) {
            const int input = w.accessor(c.times, "SCALAR");
            const int output = w.accessor(c.values, c.path == "rotation" ? "VEC4" : "VEC3");
            animation["samplers"].push_back({{"input", input}, {"output", output}});
            animation["channels"].push_back(
                {{"sampler", animation["samplers"].size() - 1}, {"target", {{"node", c.node}, {"path", c.path}}}});
        }
        w.doc["animations"].push_back(animation);
    }
    const fs::path path = fs::path(testScratchDir("keyframes-scene-" + name)) / (name + ".gltf");
    w.write(path.string());
    return path;
}

}  // namespace

TEST(Keyframes, ConstantChannelsMoveNothingAndMayHoldLights) {
    // Exporters write constant channels for every node: here the floor's and the lamp's, the
    // lamp's at another height than its rest pose (constant all the same). Only Mover moves.
    const fs::path file = writeAnimatedScene(
        "constant", {{{0, "translation", {0, 1}, {0, 0, 0, 0, 0, 0}},
                      {2, "translation", {0, 1}, {0, 4, 0, 0, 4, 0}},
                      {1, "translation", {0, 1}, {0, 1, 0, 1, 1, 0}}}});
    Warnings warnings;
    Scene scene = loadGltfScene(file.string(), warnings);
    const Animation a = Animation::fromGltf(scene, -1, 10, "test");
    EXPECT_EQ(a.lastFrame(), 10);
    EXPECT_EQ(a.movedNodes(), std::vector<int>{1});
    EXPECT_NO_THROW(checkLightsAreStatic(scene, a, "test"));
    // Frame 0's pose is the run's rest pose: the lamp shines from its animated height.
    scene.setRestPose(a.localsAt(0));
    EXPECT_NEAR(double(scene.lights.at(0).position.y) + scene.worldOrigin.y, 4.0, 1e-6);
}

TEST(Keyframes, AMovingLightIsRefusedWithItsNodeNamed) {
    const fs::path file = writeAnimatedScene("lamp", {{{2, "translation", {0, 1}, {0, 3, 0, 1, 3, 0}}}});
    Warnings warnings;
    const Scene scene = loadGltfScene(file.string(), warnings);
    const Animation a = Animation::fromGltf(scene, -1, 24, "lamp.gltf (--animation gltf)");
    try {
        checkLightsAreStatic(scene, a, "lamp.gltf (--animation gltf)");
        FAIL() << "a moving light must be refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("node 'Lamp'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("lights must be static"), std::string::npos) << e.what();
    }
}

TEST(Keyframes, AnimationsPlayedTogetherMustNotDriveTheSameProperty) {
    const fs::path file = writeAnimatedScene("clash", {{{1, "translation", {0, 1}, {0, 1, 0, 1, 1, 0}}},
                                                       {{1, "translation", {0, 2}, {0, 1, 0, 0, 2, 0}}}});
    Warnings warnings;
    const Scene scene = loadGltfScene(file.string(), warnings);
    try {
        Animation::fromGltf(scene, -1, 24, "clash.gltf (--animation gltf)");
        FAIL() << "two animations drive Mover's translation";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("node 'Mover'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("gltf:N"), std::string::npos) << e.what();
    }
    // Either alone is fine, each with its own length.
    EXPECT_EQ(Animation::fromGltf(scene, 0, 24, "t").lastFrame(), 24);
    EXPECT_EQ(Animation::fromGltf(scene, 1, 24, "t").lastFrame(), 48);
}

TEST(Keyframes, MalformedSamplersAreRefusedNamingThePlace) {
    struct Case {
        std::vector<ChannelSpec> channels;
        std::string message;
    };
    const std::vector<Case> cases = {
        {{{1, "translation", {0, 1, 1}, {0, 0, 0, 1, 1, 1, 2, 2, 2}}}, "strictly increase"},
        {{{1, "translation", {-1, 1}, {0, 0, 0, 1, 1, 1}}}, "negative"},
        {{{1, "translation", {0, 1}, {0, 0, 0, 1, 1, 1, 2, 2, 2}}}, "need 6"},
        {{{1, "rotation", {0, 1}, {0, 0, 0, 0, 0, 0, 0, 1}}}, "zero quaternion"},
        {{{1, "scale", {0, 1}, {1, 1, 1, 0, 0, 0}}}, ""},  // valid glTF: hides the node (below)
    };
    for (size_t i = 0; i < cases.size(); ++i) {
        SCOPED_TRACE(i);
        const fs::path file = writeAnimatedScene("bad" + std::to_string(i), {cases[i].channels});
        Warnings warnings;
        if (cases[i].message.empty()) {
            const Scene scene = loadGltfScene(file.string(), warnings);
            // A scale animated to zero is how glTF animates visibility (docs/design.md §3): the node
            // moves, and is hidden at frame 24.
            const Animation anim = Animation::fromGltf(scene, -1, 24, "t");
            EXPECT_EQ(anim.lastFrame(), 24);
            ASSERT_EQ(anim.movedNodes().size(), 1u);
            EXPECT_EQ(scene.nodes[size_t(anim.movedNodes()[0])].name, "Mover");
            EXPECT_FALSE(scene.worldTransforms(anim.poseAt(24).locals)[size_t(anim.movedNodes()[0])].isInvertible());
            continue;
        }
        try {
            loadGltfScene(file.string(), warnings);
            FAIL() << "expected: " << cases[i].message;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(cases[i].message), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("animations[0]"), std::string::npos) << e.what();
        }
    }
}

TEST(Keyframes, AGltfAnimationRendersIncrementallyAsAFullRecomputationWould) {
    // The box slides and turns over the floor for 1 s under the lamp (LINEAR translation, STEP
    // rotation), sampled at 8 fps: frames 0..8, each incremental frame bit-identical to a
    // from-scratch one, and the frame count from the keys.
    const auto q = aboutMinusZ(30);
    const fs::path file = writeAnimatedScene(
        "render", {{{1, "translation", {0, 1}, {-0.5f, 0.3f, 0, 0.5f, 0.3f, 0}},
                    {1, "rotation", {0, 0.5f}, {0, 0, 0, 1, float(q[0]), float(q[1]), float(q[2]), float(q[3])}}}});
    const fs::path out = testScratchDir("keyframes-render");
    const std::string common = "render " + file.string() + " --animation gltf --fps 8 --photons 20000 --no-exr --quiet";
    const CommandResult incremental = runQsgi(common + " --out " + (out / "incremental").string());
    ASSERT_EQ(incremental.exitCode, 0) << incremental.output;
    const CommandResult full = runQsgi(common + " --full-recompute --out " + (out / "full").string());
    ASSERT_EQ(full.exitCode, 0) << full.output;
    for (int frame = 0; frame <= 8; ++frame) {
        char name[32];
        std::snprintf(name, sizeof name, "frame_%04d.ply", frame);
        const std::string a = readFileBytes(out / "incremental" / name);
        ASSERT_FALSE(a.empty()) << name;
        EXPECT_EQ(a, readFileBytes(out / "full" / name)) << name;
    }
    EXPECT_FALSE(fs::exists(out / "incremental" / "frame_0009.ply"));
    // The box moved: frame 8's PLY differs from frame 0's.
    EXPECT_NE(readFileBytes(out / "full" / "frame_0000.ply"), readFileBytes(out / "full" / "frame_0008.ply"));
}

namespace {
// Pixels of an EXR with any red, and their mean column.
std::pair<size_t, double> litPixels(const fs::path& exr) {
    auto in = OIIO::ImageInput::open(exr.string());
    if (!in) return {0, 0};
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
    size_t lit = 0;
    double columns = 0;
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x)
            if (pixels[(size_t(y) * size_t(spec.width) + size_t(x)) * size_t(spec.nchannels)] > 0) {
                ++lit;
                columns += x;
            }
    return {lit, lit ? columns / double(lit) : 0};
}
}  // namespace

TEST(Keyframes, AnAnimatedOrthographicCameraPansTheView) {
    // A glowing 1 m quad facing +z, and an orthographic camera (xmag = ymag = 1: a 2 m square view)
    // 2 m in front of it, panned 0.5 m along +x over 1 s. At 64×64 pixels the quad covers the
    // middle 32×32 at first, then the same 32×32 shifted left by a quarter of the view: 16 pixels.
    testscenes::GltfWriter w;
    using nlohmann::json;
    const int positions = w.accessor({-0.5f, -0.5f, 0, 0.5f, -0.5f, 0, 0.5f, 0.5f, 0, -0.5f, 0.5f, 0}, "VEC3");
    const int indices = w.indices({0, 1, 2, 0, 2, 3});
    w.doc["meshes"] = json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", positions}}}, {"indices", indices},
                                                               {"material", 0}}})}}});
    w.doc["materials"] = json::array({{{"emissiveFactor", {1, 1, 1}}}});
    w.doc["cameras"] = json::array({{{"type", "orthographic"},
                                     {"orthographic", {{"xmag", 1}, {"ymag", 1}, {"znear", 0.01}, {"zfar", 10}}}}});
    const int quad = w.node({{"name", "Quad"}, {"mesh", 0}});
    const int camera = w.node({{"name", "Camera"}, {"camera", 0}, {"translation", {0, 0, 2}}});
    w.doc["scenes"] = json::array({{{"nodes", {quad, camera}}}});
    const int times = w.accessor({0, 1}, "SCALAR");
    const int pan = w.accessor({0, 0, 2, 0.5f, 0, 2}, "VEC3");
    w.doc["animations"] = json::array({{{"samplers", json::array({{{"input", times}, {"output", pan}}})},
                                        {"channels", json::array({{{"sampler", 0}, {"target", {{"node", camera}, {"path", "translation"}}}}})}}});
    const fs::path dir = testScratchDir("keyframes-camera");
    w.write((dir / "camera.gltf").string());
    const CommandResult r = runQsgi("render " + (dir / "camera.gltf").string() +
                                    " --animation gltf --fps 2 --photons 1000 --width 64 --height 64 --quiet --out " +
                                    (dir / "out").string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const auto [lit0, column0] = litPixels(dir / "out/frame_0000.exr");
    const auto [lit2, column2] = litPixels(dir / "out/frame_0002.exr");
    EXPECT_EQ(lit0, 32u * 32u);
    EXPECT_EQ(lit2, 32u * 32u);
    EXPECT_NEAR(column0, 31.5, 1e-9);
    EXPECT_NEAR(column2, 31.5 - 16, 1e-9);
    // The camera alone moves: the quad is static geometry, its PLY the same in every frame.
    EXPECT_EQ(readFileBytes(dir / "out/frame_0000.ply"), readFileBytes(dir / "out/frame_0002.ply"));
}
