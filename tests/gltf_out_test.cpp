// --gltf-out (issue 11): every frame_NNNN.glb passes the Khronos glTF-Validator with no error, and
// an independent reader (glTF Transform, through scripts/gltf-check/check.mjs) finds in it the
// frame's posed geometry and radiance equal to the PLY's: _RADIANCE = B/π, COLOR_0 = min(1,
// exposure·B/π). Both tools are installed by scripts/setup.sh (npm ci in scripts/gltf-check).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <regex>

#include "output/ply_reader.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {

// The checkers are a test dependency (scripts/setup.sh --test installs them), so their absence
// fails the tests rather than skipping them: a skip would let CI pass without checking a file.
std::string checkerCommand(const fs::path& glb, const std::string& options) {
    const fs::path tool = sourceDir() / "scripts/gltf-check";
    if (!fs::exists(tool / "node_modules/gltf-validator"))
        throw std::runtime_error("the glTF checkers are not installed: run scripts/setup.sh (npm ci in " +
                                 tool.string() + ")");
    return "node " + (tool / "check.mjs").string() + options + " " + glb.string();
}

nlohmann::json checkGlb(const fs::path& glb) {
    const CommandResult r = runCommand(checkerCommand(glb, " --json"));
    if (r.exitCode != 0) throw std::runtime_error("check.mjs failed on " + glb.string() + ": " + r.output);
    // runCommand adds stderr to the output, but check.mjs writes there only when it fails.
    return nlohmann::json::parse(r.output);
}

// Relative difference, with a floor for values near zero.
double relativeDifference(double a, double b) { return std::fabs(a - b) / std::max({std::fabs(a), std::fabs(b), 1e-6}); }

std::string frameName(int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d", frame);
    return name;
}

}  // namespace

// Frames 0 to 2 of the animated data/cornell, rendered once for the suite: every test here reads
// them, and the render is the suite's main cost.
class GltfOut : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        out_ = testScratchDir("gltf-out");
        render_ = runQsgi("render " + common() + " --threads 2 --out " + (out_ / "a").string());
    }
    static std::string common() {
        return (sourceDir() / "data/cornell/cornell.gltf").string() + " --animation " +
               (sourceDir() / "data/cornell/animation.json").string() +
               " --frames 0:2 --photons 20000 --no-exr --gltf-out --quiet" + kCheapSecondPass;
    }
    static inline fs::path out_;
    static inline CommandResult render_;
};

TEST_F(GltfOut, FramesPassTheKhronosValidatorAndCarryThePlysGeometryAndRadiance) {
    ASSERT_EQ(render_.exitCode, 0) << render_.output;

    std::vector<float> firstPositions;
    for (int frame = 0; frame <= 2; ++frame) {
        SCOPED_TRACE("frame " + std::to_string(frame));
        const std::string name = frameName(frame);
        nlohmann::json glb;
        ASSERT_NO_THROW(glb = checkGlb(out_ / "a" / (name + ".glb")));
        const nlohmann::json& v = glb["validator"];
        EXPECT_EQ(v["errors"], 0) << v["messages"].dump(1);
        EXPECT_EQ(v["warnings"], 0) << v["messages"].dump(1);

        const VertexRadiosityPly ply = readVertexRadiosityPly((out_ / "a" / (name + ".ply")).string());
        const size_t n = ply.positions.size();
        const auto position = glb["position"].get<std::vector<float>>();
        const auto radiance = glb["radiance"].get<std::vector<float>>();
        const auto colour = glb["color"].get<std::vector<float>>();
        const auto irradiance = glb["irradiance"].get<std::vector<float>>();
        const auto translation = glb["translation"].get<std::vector<double>>();
        ASSERT_EQ(position.size(), 3 * n);
        ASSERT_EQ(radiance.size(), 3 * n);
        ASSERT_EQ(colour.size(), 3 * n);
        ASSERT_EQ(irradiance.size(), 3 * n);
        EXPECT_EQ(glb["indices"].get<size_t>(), 3 * ply.triangles.size());
        const double exposure = glb["extras"]["qsgi"]["exposure"].get<double>();
        ASSERT_GT(exposure, 0);
        double worstPosition = 0, worstRadiance = 0, worstColour = 0;
        size_t clamped = 0;
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) {
                // Node translation + relative position = the PLY's world position (both float).
                const double world = double(position[3 * i + c]) + translation[size_t(c)];
                worstPosition = std::max(worstPosition, std::fabs(world - double(ply.positions[i][c])));
                const double b = ply.radiosity[i][c];
                worstRadiance = std::max(worstRadiance, relativeDifference(radiance[3 * i + c], b / M_PI));
                const double expectedColour = std::min(1.0, exposure * double(radiance[3 * i + c]));
                worstColour = std::max(worstColour, std::fabs(double(colour[3 * i + c]) - expectedColour));
                clamped += expectedColour == 1.0;
                EXPECT_TRUE(std::isfinite(irradiance[3 * i + c]) && irradiance[3 * i + c] >= 0);
            }
        // Float rounding of a coordinate of magnitude ≤ 2 (Cornell's box), of B/π, of a colour.
        EXPECT_LT(worstPosition, 1e-6);
        EXPECT_LT(worstRadiance, 1e-6);
        EXPECT_LT(worstColour, 1e-6);
        EXPECT_GT(clamped, 0u);  // the emitter is brighter than white: the clamp is exercised
        // The geometry is posed per frame: the block moves between frames 0 and 2.
        if (frame == 0) firstPositions = position;
        if (frame == 2) {
            EXPECT_NE(position, firstPositions);
        }
    }

    // Same inputs and seed, other thread count: the same bytes.
    const CommandResult one = runQsgi("render " + common() + " --threads 1 --out " + (out_ / "b").string());
    ASSERT_EQ(one.exitCode, 0) << one.output;
    for (const char* frame : {"frame_0000.glb", "frame_0002.glb"})
        EXPECT_EQ(readFileBytes(out_ / "a" / frame), readFileBytes(out_ / "b" / frame)) << frame;
}

// Without --json the checker prints a summary for people (issue 35): a few lines, not the ~1 MB of
// arrays, with the validator's counts and each primitive's attributes and vertex count.
TEST_F(GltfOut, TheCheckersSummaryIsShortWithTheValidatorsCountsAndTheVertexCount) {
    ASSERT_EQ(render_.exitCode, 0) << render_.output;
    const fs::path glb = out_ / "a" / (frameName(0) + ".glb");
    std::string command;
    ASSERT_NO_THROW(command = checkerCommand(glb, ""));
    const CommandResult r = runCommand(command);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_LT(r.output.size(), 4096u) << r.output;
    EXPECT_NE(r.output.find(": 0 errors, 0 warnings,"), std::string::npos) << r.output;

    const size_t n = readVertexRadiosityPly((out_ / "a" / (frameName(0) + ".ply")).string()).positions.size();
    std::smatch position;
    ASSERT_TRUE(std::regex_search(r.output, position, std::regex("\\n +POSITION +count ([0-9]+) +VEC3 FLOAT\\n")))
        << r.output;
    EXPECT_EQ(std::stoul(position[1].str()), n) << r.output;
}
