// `qsgi inspect` (issue 22): what a render would see, from the same loading and checks as a
// render — so its counts match the scene's construction, its shares of power add up, a config's
// lights and radius are included, the render's warnings are listed, and bad input gets exactly
// the render's message and exit code.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string cornell() { return (sourceDir() / "data/cornell/cornell.gltf").string(); }

json inspectJson(const std::string& arguments) {
    const CommandResult r = runQsgi("inspect " + arguments + " --json");
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return json::parse(r.output);
}

}  // namespace

TEST(Inspect, CornellCountsWhatItsGeneratorBuilt) {
    // scripts/make_cornell.py: the block is a cube of 8 x 8 cells a face, two triangles a cell.
    const json r = inspectJson(cornell() + " --animation " + (sourceDir() / "data/cornell/animation.json").string());
    EXPECT_EQ(r["animation"]["moved_nodes"], json::array({"Block"}));
    EXPECT_EQ(r["animation"]["dynamic_triangles"].get<uint64_t>(), 6u * 8 * 8 * 2);
    EXPECT_NEAR(r["animation"]["dynamic_fraction"].get<double>(),
                768.0 / r["scene"]["triangles"].get<double>(), 1e-12);
    EXPECT_EQ(r["animation"]["frames"].get<int>(), 60);
    // Lit by its ceiling panel alone: all the power is the emissive surfaces'.
    EXPECT_TRUE(r["lights"].empty());
    EXPECT_DOUBLE_EQ(r["emissive_surfaces"]["share"].get<double>(), 1.0);
    // The default radius: 1.5 % of the animation's diagonal.
    EXPECT_NEAR(r["radius"]["value"].get<double>(), 0.015 * r["animation"]["diagonal"].get<double>(), 1e-6);
    EXPECT_TRUE(r["warnings"].empty());

    const CommandResult text = runQsgi("inspect " + cornell());
    ASSERT_EQ(text.exitCode, 0) << text.output;
    EXPECT_NE(text.output.find("moving: nothing"), std::string::npos) << text.output;
}

TEST(Inspect, IncludesAConfigsLightsAndRadiusAndTheRendersWarnings) {
    const fs::path dir = testScratchDir("inspect");
    // Two point lights of intensity 1 and 3 W/sr beside the panel: power 4 pi I each.
    const fs::path config = dir / "lights.json";
    std::ofstream(config) << R"({"radius": 0.02, "lights": [)"
                          << R"({"type": "point", "position": [0, 0.5, 0], "intensity": [1, 1, 1]},)"
                          << R"({"type": "point", "position": [0, -0.5, 0], "intensity": [3, 3, 3]}]})";
    const json r = inspectJson(cornell() + " --config " + config.string());
    ASSERT_EQ(r["lights"].size(), 2u);
    EXPECT_EQ(r["lights"][0]["from"], "config");
    const double p0 = r["lights"][0]["power_w"].get<double>(), p1 = r["lights"][1]["power_w"].get<double>();
    EXPECT_NEAR(p0, 4 * M_PI, 1e-4);
    EXPECT_NEAR(p1, 12 * M_PI, 1e-4);
    const double shares = r["lights"][0]["share"].get<double>() + r["lights"][1]["share"].get<double>() +
                          r["emissive_surfaces"]["share"].get<double>();
    EXPECT_NEAR(shares, 1.0, 1e-9);
    EXPECT_NEAR(r["lights"][1]["share"].get<double>() / r["lights"][0]["share"].get<double>(), 3.0, 1e-6);
    EXPECT_FLOAT_EQ(r["radius"]["value"].get<float>(), 0.02f);

    // A scene with no camera: the render would warn that it frames the bounds; so does inspect.
    const json noCamera = inspectJson((sourceDir() / "tests/data/good/base.gltf").string() + " --config " + config.string());
    ASSERT_EQ(noCamera["warnings"].size(), 1u) << noCamera.dump(2);
    EXPECT_NE(noCamera["warnings"][0].get<std::string>().find("no camera"), std::string::npos);
}

TEST(Inspect, BadInputGetsTheRendersMessageAndExitCode) {
    const fs::path dir = testScratchDir("inspect-bad");
    for (const char* bad : {"tests/data/bad/gltf/accessor_past_view.gltf", "tests/data/bad/gltf/accessor_missing.gltf"}) {
        const std::string scene = (sourceDir() / bad).string();
        const CommandResult inspect = runQsgi("inspect " + scene);
        const CommandResult render = runQsgi("render " + scene + " --out " + (dir / "out").string());
        EXPECT_EQ(inspect.exitCode, 2) << inspect.output;
        EXPECT_EQ(inspect.output, render.output);
        EXPECT_EQ(std::count(inspect.output.begin(), inspect.output.end(), '\n'), 1) << inspect.output;
    }
    EXPECT_FALSE(fs::exists(dir / "out"));
}

// data/walker (scripts/make_walker.py): a skinned figure animated in the glTF file itself — 4 s
// of "Walk", the figure sliding and its legs swinging, constant channels on the hips (which
// therefore do not move), a 60 W/sr lamp and a camera node.
TEST(Inspect, WalkerShowsItsSkinnedAnimationAtTheChosenRate) {
    const std::string walker = (sourceDir() / "data/walker/walker.gltf").string();
    const json r = inspectJson(walker + " --animation gltf");
    EXPECT_EQ(r["animation"]["source"], "gltf");
    EXPECT_EQ(r["animation"]["frames"].get<int>(), 4 * 24 + 1);
    ASSERT_EQ(r["animation"]["gltf_animations"].size(), 1u);
    EXPECT_EQ(r["animation"]["gltf_animations"][0]["name"], "Walk");
    EXPECT_DOUBLE_EQ(r["animation"]["gltf_animations"][0]["seconds"].get<double>(), 4.0);
    EXPECT_EQ(r["animation"]["moved_nodes"], json::array({"Walker", "LeftLeg", "RightLeg"}));
    // The figure moves, the room and its furniture do not.
    const double dynamic = r["animation"]["dynamic_triangles"].get<double>();
    EXPECT_GT(dynamic, 0);
    EXPECT_LT(dynamic, r["scene"]["triangles"].get<double>());
    ASSERT_EQ(r["lights"].size(), 1u);
    EXPECT_EQ(r["lights"][0]["name"], "Lamp");
    EXPECT_NEAR(r["lights"][0]["power_w"].get<double>(), 4 * M_PI * 60, 1e-3);
    EXPECT_EQ(r["cameras"]["render"]["from"], "node 'Camera'");
    EXPECT_TRUE(r["warnings"].empty()) << r["warnings"].dump();
    // Sampled at 10 frames a second: 41 frames over the same 4 s.
    EXPECT_EQ(inspectJson(walker + " --animation gltf --fps 10")["animation"]["frames"].get<int>(), 41);
}
