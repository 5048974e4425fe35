// `qsgi inspect` (issue 22): what a render would see, from the same loading and checks as a
// render — so its counts match the scene's construction, its shares of power add up, a config's
// lights and radius are included, the render's warnings are listed, and bad input gets exactly
// the render's message and exit code.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <nlohmann/json.hpp>

#include "output/ply_reader.h"
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
    // (Its one quad, 4 r across many times, is warned about too: mesh_resolution.h.)
    const json noCamera = inspectJson((sourceDir() / "tests/data/good/base.gltf").string() + " --config " + config.string());
    ASSERT_EQ(noCamera["warnings"].size(), 2u) << noCamera.dump(2);
    EXPECT_NE(noCamera["warnings"][0].get<std::string>().find("no camera"), std::string::npos);
    EXPECT_NE(noCamera["warnings"][1].get<std::string>().find("longer than 4 r"), std::string::npos);
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

namespace {

// The bounds of the positions a render writes into its first frame's PLY.
std::pair<std::array<double, 3>, std::array<double, 3>> plyBounds(const fs::path& ply) {
    const qsgi::VertexRadiosityPly read = qsgi::readVertexRadiosityPly(ply.string());
    std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (const qsgi::Vec3f& p : read.positions)
        for (int c = 0; c < 3; ++c) {
            lo[size_t(c)] = std::min(lo[size_t(c)], double(p[c]));
            hi[size_t(c)] = std::max(hi[size_t(c)], double(p[c]));
        }
    return {lo, hi};
}

// data/cornell moved far from the origin by a new root node (its buffer copied beside it).
fs::path translatedCornell(const fs::path& dir, const std::array<double, 3>& offset) {
    json doc = json::parse(readFileBytes(sourceDir() / "data/cornell/cornell.gltf"));
    json root = {{"name", "Offset"}, {"translation", offset}, {"children", doc["scenes"][0]["nodes"]}};
    doc["nodes"].push_back(root);
    doc["scenes"][0]["nodes"] = json::array({doc["nodes"].size() - 1});
    fs::copy_file(sourceDir() / "data/cornell/cornell.bin", dir / "cornell.bin", fs::copy_options::overwrite_existing);
    std::ofstream(dir / "translated.gltf") << doc.dump();
    return dir / "translated.gltf";
}

}  // namespace

// Bounds are in the file's world coordinates — what the PLYs hold and what a config's lights and
// camera are given in — not in the re-centred coordinates the renderer works in.
TEST(Inspect, BoundsAreTheFilesWorldCoordinatesAsThePlyHoldsThem) {
    const fs::path dir = testScratchDir("inspect-bounds");
    const std::array<double, 3> offset{1000.5, -20.25, 300};
    for (const fs::path& scene : {sourceDir() / "data/cornell/cornell.gltf", translatedCornell(dir, offset)}) {
        SCOPED_TRACE(scene.string());
        const fs::path out = dir / ("out-" + scene.stem().string());
        fs::remove_all(out);
        ASSERT_EQ(runQsgi("render " + scene.string() + " --photons 2000 --no-exr --quiet --out " + out.string()).exitCode, 0);
        const auto [lo, hi] = plyBounds(out / "frame_0000.ply");
        const json r = inspectJson(scene.string());
        for (size_t c = 0; c < 3; ++c) {
            // The PLY stores floats: the inspected bounds agree to float precision at that magnitude.
            const double tolerance = 1e-6 * std::max(1.0, std::fabs(hi[c]) + std::fabs(lo[c]));
            EXPECT_NEAR(r["scene"]["bounds"]["min"][c].get<double>(), lo[c], tolerance) << "axis " << c;
            EXPECT_NEAR(r["scene"]["bounds"]["max"][c].get<double>(), hi[c], tolerance) << "axis " << c;
            EXPECT_NEAR(r["animation"]["bounds"]["min"][c].get<double>(), lo[c], tolerance) << "axis " << c;
        }
        // data/cornell's box stands on its floor at y = 0 (scripts/make_cornell.py).
        const double floor = scene.stem() == "cornell" ? 0.0 : offset[1];
        EXPECT_NEAR(r["scene"]["bounds"]["min"][1].get<double>(), floor, 1e-4);
        EXPECT_NEAR(r["scene"]["bounds"]["max"][1].get<double>(), floor + 2, 1e-4);
    }
}

// A scene without lights is exactly when a user needs inspect: to see the bounds before writing
// lights into a config. It is reported, exit 0; the render still refuses it.
TEST(Inspect, ASceneWithoutLightsIsReportedNotRefused) {
    const std::string dark = (sourceDir() / "tests/data/bad/gltf/no_lights.gltf").string();
    const CommandResult text = runQsgi("inspect " + dark);
    ASSERT_EQ(text.exitCode, 0) << text.output;
    EXPECT_NE(text.output.find("lights     none"), std::string::npos) << text.output;
    for (const char* way : {"\"lights\" in a config", "--sky R,G,B", "--environment FILE"})
        EXPECT_NE(text.output.find(way), std::string::npos) << text.output;
    const json r = inspectJson(dark);
    EXPECT_FALSE(r["lit"].get<bool>());
    EXPECT_GT(r["scene"]["triangles"].get<int>(), 0);
    EXPECT_NE(r["output_folder"]["render"].get<std::string>().find("no lights"), std::string::npos);
    const fs::path out = fs::path(testScratchDir("inspect-dark")) / "out";
    EXPECT_EQ(runQsgi("render " + dark + " --out " + out.string()).exitCode, 2);

    // With a sky the scene is lit, and the sky is all its power: π R² ∫ L dω = π R² 4π L.
    const CommandResult sky = runQsgi("inspect " + dark + " --sky 0.5");
    ASSERT_EQ(sky.exitCode, 0) << sky.output;
    EXPECT_NE(sky.output.find("  sky (1 x 1 pixels)"), std::string::npos) << sky.output;
    const json lit = inspectJson(dark + " --sky 0.5");
    EXPECT_TRUE(lit["lit"].get<bool>());
    EXPECT_EQ(lit["environment"]["type"], "sky");
    EXPECT_DOUBLE_EQ(lit["environment"]["share"].get<double>(), 1.0);
}

// Every render option is accepted (change a render's verb to check it), and the report says which
// options differ from the defaults and what the render would do with its output folder.
TEST(Inspect, TakesARendersCommandLineAndReportsItsOptionsAndTheOutputFolder) {
    const fs::path out = fs::path(testScratchDir("inspect-options")) / "out";
    const std::string scene = cornell() + " --animation " + (sourceDir() / "data/cornell/animation.json").string();
    const std::string render = scene + " --estimator detp --photons 20000 --frames 0:2 --no-exr --width 20 --height 15";
    json r = inspectJson(render + " --out " + out.string());
    EXPECT_EQ(r["options_set"]["estimator"], "detp");
    EXPECT_EQ(r["options_set"]["photons"], 20000);
    EXPECT_EQ(r["options_set"]["exr"], false);
    EXPECT_FALSE(r["options_set"].contains("radius")) << "the default radius is no choice of the user's";
    EXPECT_FALSE(r["options_set"].contains("seed"));
    EXPECT_EQ(r["output_folder"]["state"], "absent");
    EXPECT_FALSE(fs::exists(out)) << "inspect writes nothing";

    ASSERT_EQ(runQsgi("render " + render + " --frames 0:1 --quiet --out " + out.string()).exitCode, 0);
    r = inspectJson(render + " --resume --out " + out.string());
    EXPECT_EQ(r["output_folder"]["state"], "this run");
    EXPECT_EQ(r["output_folder"]["complete_frames"], json::array({0, 1}));
    EXPECT_NE(r["output_folder"]["render"].get<std::string>().find("resumes at frame 2"), std::string::npos)
        << r["output_folder"].dump();

    r = inspectJson(render + " --photons 30000 --out " + out.string());
    EXPECT_EQ(r["output_folder"]["state"], "another run");
    EXPECT_EQ(r["output_folder"]["differences"], json::array({"photons 20000 there, 30000 here"}));
    EXPECT_NE(r["output_folder"]["render"].get<std::string>().find("refuses"), std::string::npos);
}

// A mesh too coarse for the radius (issue 35): a quad of two triangles, each edge many radii long,
// carries no shadow or patch of light smaller than itself. inspect counts the triangles with an
// edge past 4 r, their vertices and their share of the area, and the run warns; data/cornell's
// grids are within 4 r and get no warning.
TEST(Inspect, TrianglesLongerThanFourRadiiAreCountedAndWarnedAbout) {
    const json quad = inspectJson((sourceDir() / "tests/data/good/base.gltf").string() + " --sky 1 --radius 0.05");
    const json& m = quad["mesh_resolution"];
    EXPECT_DOUBLE_EQ(m["edge_limit"].get<double>(), 4 * double(0.05f));
    EXPECT_EQ(m["coarse_triangles"].get<int>(), 2);
    EXPECT_EQ(m["coarse_vertices"].get<int>(), 4);
    EXPECT_DOUBLE_EQ(m["coarse_area_share"].get<double>(), 1.0);
    bool warned = false;
    for (const auto& w : quad["warnings"]) warned = warned || w.get<std::string>().find("2 of 2 triangles have an edge longer than 4 r") != std::string::npos;
    EXPECT_TRUE(warned) << quad["warnings"].dump();
    // A radius a quarter of the quad's side or more: nothing is coarse.
    EXPECT_EQ(inspectJson((sourceDir() / "tests/data/good/base.gltf").string() + " --sky 1 --radius 1")["mesh_resolution"]
                  ["coarse_triangles"].get<int>(), 0);
    const json cornellReport = inspectJson(cornell());
    EXPECT_EQ(cornellReport["mesh_resolution"]["coarse_triangles"].get<int>(), 0);
    EXPECT_LE(cornellReport["mesh_resolution"]["longest_edge"].get<double>(), cornellReport["mesh_resolution"]["edge_limit"].get<double>());
}

// `inspect --scenes LIST` checks many scenes in one process: one JSON line a listed scene, whose
// exit code, error line and report are what `qsgi inspect SCENE --json` gives for it alone — a
// good scene, a hostile file, a skinned one and an absent path, in one list, a blank line skipped.
TEST(Inspect, ScenesListAnswersForEachSceneAsItAloneWould) {
    const fs::path dir = testScratchDir("inspect-scenes");
    const std::vector<std::string> scenes = {cornell(), (sourceDir() / "tests/data/bad/gltf/accessor_past_view.gltf").string(),
                                             (sourceDir() / "data/walker/walker.gltf").string(), (dir / "absent.gltf").string()};
    const fs::path list = dir / "scenes.txt";
    {
        std::ofstream out(list);
        out << scenes[0] << "\n" << scenes[1] << "\n\n" << scenes[2] << "\r\n" << scenes[3];
    }
    const std::string qsgi = QSGI_CLI;
    const fs::path stderrFile = dir / "stderr.txt";
    // In a subshell of its own: runCommand sends the whole line's stderr to its output.
    const auto stdoutOnly = [&](const std::string& arguments) {
        return runCommand("(" + qsgi + " " + arguments + " 2>'" + stderrFile.string() + "')");
    };
    const CommandResult batch = stdoutOnly("inspect --scenes '" + list.string() + "' --json");
    EXPECT_EQ(batch.exitCode, 2) << "a refused scene makes the whole command exit 2";
    EXPECT_EQ(readFileBytes(stderrFile), "") << "each scene's error is in its line";
    std::vector<json> lines;
    std::istringstream in(batch.output);
    for (std::string line; std::getline(in, line);) lines.push_back(json::parse(line));
    ASSERT_EQ(lines.size(), scenes.size()) << batch.output;
    for (size_t i = 0; i < scenes.size(); ++i) {
        SCOPED_TRACE(scenes[i]);
        const CommandResult alone = stdoutOnly("inspect '" + scenes[i] + "' --json");
        const std::string aloneStderr = readFileBytes(stderrFile);
        EXPECT_EQ(lines[i]["scene"], scenes[i]);
        EXPECT_EQ(lines[i]["exit"].get<int>(), alone.exitCode);
        if (alone.exitCode == 0) {
            EXPECT_EQ(lines[i]["error"], "");
            EXPECT_EQ(lines[i]["report"], json::parse(alone.output));
        } else {
            EXPECT_EQ(lines[i]["error"].get<std::string>() + "\n", aloneStderr);
            EXPECT_TRUE(lines[i]["report"].is_null());
        }
    }
    EXPECT_EQ(lines[0]["exit"], 0);
    EXPECT_EQ(lines[1]["exit"], 2);
    EXPECT_EQ(lines[3]["exit"], 2);

    // A scene and a list at once, or a list that is not there: one line naming the problem, exit 2.
    const CommandResult both = runQsgi("inspect " + cornell() + " --scenes '" + list.string() + "'");
    EXPECT_EQ(both.exitCode, 2) << both.output;
    EXPECT_NE(both.output.find("--scenes"), std::string::npos) << both.output;
    EXPECT_EQ(std::count(both.output.begin(), both.output.end(), '\n'), 1) << both.output;
    const CommandResult absent = runQsgi("inspect --scenes '" + (dir / "no-list.txt").string() + "'");
    EXPECT_EQ(absent.exitCode, 2) << absent.output;
    EXPECT_NE(absent.output.find("no-list.txt"), std::string::npos) << absent.output;
    EXPECT_EQ(std::count(absent.output.begin(), absent.output.end(), '\n'), 1) << absent.output;
}
