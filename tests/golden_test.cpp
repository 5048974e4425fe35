// Golden images (docs/design.md §7, §9): fresh renders compared with committed EXRs the way CI pipelines
// guard renders. Thresholds (ImageTolerance defaults) and why:
//  - The output is deterministic, so the same build reproduces a golden bit for bit (error 0).
//  - Another compiler or CPU may round a few operations differently (FMA contraction, libm), which
//    can send a rare photon elsewhere; each photon carries ~1/N of the power, so such flips move
//    single triangles by a few percent and the image mean by far less than 0.2 %.
//  - A real change is far larger: 10x fewer photons raises the photons-only impact-count noise by
//    sqrt(10) (relative mean error ~0.3 with random photons), a changed albedo shifts whole walls by
//    several percent.
// Set QSGI_UPDATE_GOLDENS=1 (scripts/update-goldens.sh) to rewrite the goldens on purpose.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "output/image_compare.h"
#include "test_support.h"

namespace fs = std::filesystem;
using qsgi::compareImages;
using qsgi::ImageTolerance;

namespace {

struct GoldenCase {
    std::string name;
    std::string arguments;  // for qsgi render, without --out
    int frame;
};

// Test names show the case's name, not its bytes.
void PrintTo(const GoldenCase& c, std::ostream* os) { *os << c.name; }

// The paper's method: every watt from the photons' density estimate.
const std::string kPhotonsOnly = " --direct photons --gather 0";

std::vector<GoldenCase> goldenCases() {
    const std::string cornell = (sourceDir() / "data/cornell/cornell.gltf").string();
    const std::string animation = (sourceDir() / "data/cornell/animation.json").string();
    const std::string size = " --width 160 --height 120 --seed 1 --quiet";
    return {
        {"cornell_f0000", cornell + " --animation " + animation + " --frames 0:0 --photons 200000" + size, 0},
        {"cornell_f0030", cornell + " --animation " + animation + " --frames 30:30 --photons 200000" + size, 30},
        {"sphere_point_light", (sourceDir() / "tests/scenes/sphere_point_light.gltf").string() + " --photons 200000" + size, 0},
        {"plane_point_light", (sourceDir() / "tests/scenes/plane_point_light.gltf").string() + " --photons 200000" + size, 0},
        // The random sampler's renders from the photons alone, byte for byte what qsgi drew before
        // Sobol photons, exact direct light and the gather became the defaults (issues 20, 33).
        {"cornell_f0000_random",
         cornell + " --animation " + animation + " --frames 0:0 --photons 200000 --sampler random" + kPhotonsOnly + size, 0},
        {"plane_point_light_random",
         (sourceDir() / "tests/scenes/plane_point_light.gltf").string() + " --photons 200000 --sampler random" +
             kPhotonsOnly + size,
         0},
    };
}

fs::path renderFresh(const std::string& arguments, int frame, const std::string& folder) {
    const fs::path out = testScratchDir(folder);
    const CommandResult r = runQsgi("render " + arguments + " --out " + out.string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04d.exr", frame);
    return out / name;
}

fs::path failureDir() {
    const fs::path d = fs::current_path() / "golden-failures";
    fs::create_directories(d);
    return d;
}

}  // namespace

class GoldenImage : public ::testing::TestWithParam<GoldenCase> {};

TEST_P(GoldenImage, FreshRenderMatchesTheGolden) {
    const GoldenCase& c = GetParam();
    const fs::path golden = sourceDir() / "tests/golden" / (c.name + ".exr");
    const fs::path fresh = renderFresh(c.arguments, c.frame, "golden_" + c.name);
    ASSERT_TRUE(fs::exists(fresh));
    if (const char* update = std::getenv("QSGI_UPDATE_GOLDENS"); update && std::string(update) == "1") {
        fs::copy_file(fresh, golden, fs::copy_options::overwrite_existing);
        // Skipped, not passed: with the golden replaced by the fresh image nothing was compared.
        GTEST_SKIP() << "QSGI_UPDATE_GOLDENS=1: " << golden << " updated from the fresh render, not compared";
    }
    ASSERT_TRUE(fs::exists(golden)) << golden << " is missing: run scripts/update-goldens.sh";
    const ImageTolerance tolerance;
    const fs::path diff = failureDir() / (c.name + ".diff.exr");
    const auto result = compareImages(fresh, golden, tolerance, diff);
    ASSERT_TRUE(result.readable) << result.problem;
    std::printf("%s: mean relative error %.3g, failing pixels %.3g %%\n", c.name.c_str(), result.meanRelativeError,
                100 * result.failingPixelFraction);
    if (result.passes(tolerance)) {
        fs::remove(diff);
        return;
    }
    fs::copy_file(fresh, failureDir() / (c.name + ".fresh.exr"), fs::copy_options::overwrite_existing);
    ADD_FAILURE() << c.name << " differs from its golden: mean relative error " << result.meanRelativeError
                  << " (limit " << tolerance.maxMeanRelativeError << "), failing pixels " << result.failingPixelFraction
                  << " (limit " << tolerance.maxFailingPixelFraction << "). Fresh image and |difference| are in "
                  << failureDir();
}

INSTANTIATE_TEST_SUITE_P(Renders, GoldenImage, ::testing::ValuesIn(goldenCases()),
                         [](const auto& info) { return info.param.name; });

// The check must be able to fail: a photons-only render with 10x fewer photons (against the
// photons-only golden: the defaults' gather hides most of the photons' noise, by design), and a
// render with a different wall albedo (against the defaults' frame-0 golden), are both rejected.
TEST(GoldenImageCheck, CatchesFewerPhotonsAndAChangedAlbedo) {
    const fs::path golden = sourceDir() / "tests/golden/cornell_f0000.exr";
    const fs::path photonsGolden = sourceDir() / "tests/golden/cornell_f0000_random.exr";
    ASSERT_TRUE(fs::exists(golden));
    ASSERT_TRUE(fs::exists(photonsGolden));
    const GoldenCase base = goldenCases()[0];
    const ImageTolerance tolerance;

    std::string fewer = goldenCases()[4].arguments;
    fewer.replace(fewer.find("--photons 200000"), 16, "--photons 20000");
    const auto noisy = compareImages(renderFresh(fewer, 0, "golden_fewer"), photonsGolden, tolerance);
    ASSERT_TRUE(noisy.readable) << noisy.problem;
    std::printf("10x fewer photons: mean relative error %.3g, failing pixels %.3g %%\n", noisy.meanRelativeError,
                100 * noisy.failingPixelFraction);
    EXPECT_FALSE(noisy.passes(tolerance));

    // The same scene with the white material's albedo 0.725 -> 0.68.
    const std::string dir = testScratchDir("golden_albedo");
    nlohmann::json doc;
    std::ifstream(sourceDir() / "data/cornell/cornell.gltf") >> doc;
    doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"][0] = 0.68;
    std::ofstream(dir + "/cornell.gltf") << doc.dump();
    fs::copy_file(sourceDir() / "data/cornell/cornell.bin", dir + "/cornell.bin");
    std::string changed = base.arguments;
    changed.replace(0, changed.find(' '), dir + "/cornell.gltf");
    const auto tinted = compareImages(renderFresh(changed, 0, "golden_albedo_out"), golden, tolerance);
    ASSERT_TRUE(tinted.readable) << tinted.problem;
    std::printf("albedo 0.725 -> 0.68 (red channel): mean relative error %.3g, failing pixels %.3g %%\n",
                tinted.meanRelativeError, 100 * tinted.failingPixelFraction);
    EXPECT_FALSE(tinted.passes(tolerance));
}
