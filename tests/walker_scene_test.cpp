// The shipped animated example (issue 11): data/walker is what scripts/make_walker.py makes, byte
// for byte, and configs/walker.json renders it from its own glTF animation, incrementally.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "test_support.h"

namespace fs = std::filesystem;

TEST(WalkerScene, DataIsWhatTheScriptMakesAndTheConfigRendersIt) {
    const fs::path made = testScratchDir("walker-made");
    const CommandResult script =
        runCommand("python3 " + (sourceDir() / "scripts/make_walker.py").string() + " " + made.string());
    ASSERT_EQ(script.exitCode, 0) << script.output;
    for (const char* file : {"walker.gltf", "walker.bin"})
        EXPECT_EQ(readFileBytes(made / file), readFileBytes(sourceDir() / "data/walker" / file))
            << file << " differs from a fresh run of scripts/make_walker.py";

    const fs::path out = testScratchDir("walker-render");
    const CommandResult render = runQsgi("render --config " + (sourceDir() / "configs/walker.json").string() +
                                         " --frames 0:3 --photons 20000 --no-exr --quiet --out " + out.string());
    ASSERT_EQ(render.exitCode, 0) << render.output;
    const nlohmann::json timing = nlohmann::json::parse(readFileBytes(out / "timing.json"));
    ASSERT_EQ(timing["frames"].size(), 4u);
    // The figure deforms every frame, and only the paths it touches are retraced.
    for (int frame = 1; frame <= 3; ++frame) {
        const int64_t retraced = timing["frames"][frame]["paths_retraced"].get<int64_t>();
        EXPECT_GT(retraced, 0) << "frame " << frame;
        EXPECT_LT(retraced, 20000 / 4) << "frame " << frame;
    }
}
