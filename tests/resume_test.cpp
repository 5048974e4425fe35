// Crash-safe output and --resume (issue 9): a run killed at a random moment and resumed writes,
// frame file for frame file, the bytes of an uninterrupted run; SIGINT/SIGTERM stop after the
// current frame with a consistent folder; a folder made from other inputs is not resumed.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <random>
#include <set>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {

// 12 frames of data/cornell with PLY, EXR and PNG, exact direct light and a final gather (fewer
// rays than the defaults': what resuming must reproduce is the same): about 1 s on 2 cores. Every
// frame after the first is the same kind of work (an incremental update, then three files
// written), so twelve give a kill as many kinds of moment to land in as thirty did.
constexpr int kFrames = 12;
// Fewer photons under the sanitizers, where each run is slower: the same stages, files and signals.
std::string renderArguments() {
    const fs::path cornell = sourceDir() / "data" / "cornell";
    return "render " + (cornell / "cornell.gltf").string() + " --animation " + (cornell / "animation.json").string() +
           " --frames 0:" + std::to_string(kFrames - 1) + " --photons " + (kSanitized ? "30000" : "100000") +
           " --width 80 --height 60 --png --quiet" +
           kCheapSecondPass;
}

struct SignalledRun {
    int exitCode;
    std::string output;
};

// Starts `qsgi arguments` and sends it `signal` after `seconds` (if it still runs). With
// `afterStart`, the clock starts when that file appears (the run has begun), not at launch.
SignalledRun runAndSignal(const std::string& arguments, const char* signal, double seconds, const fs::path& scratch,
                          const fs::path& afterStart = {}) {
    const fs::path log = scratch / "signalled.log", rc = scratch / "signalled.rc";
    const std::string waitForStart =
        afterStart.empty() ? "" : "for i in $(seq 12000); do [ -e " + afterStart.string() + " ] && break; sleep 0.01; done; ";
    const std::string command = std::string(QSGI_CLI) + " " + arguments + " 2>" + log.string() + " & pid=$!; " +
                                waitForStart + "sleep " + std::to_string(seconds) + "; kill -" + signal +
                                " $pid 2>/dev/null; wait $pid; echo $? > " + rc.string();
    EXPECT_EQ(std::system(command.c_str()), 0);
    return {std::stoi(readFileBytes(rc)), readFileBytes(log)};
}

void expectSameFrameFiles(const fs::path& reference, const fs::path& resumed) {
    const std::set<std::string> names = frameFiles(reference);
    ASSERT_EQ(names.size(), size_t(3 * kFrames));
    EXPECT_EQ(frameFiles(resumed), names);
    for (const std::string& name : names) EXPECT_EQ(readFileBytes(reference / name), readFileBytes(resumed / name)) << name;
}


double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

TEST(Resume, RunKilledAtRandomMomentsResumesToTheBytesOfAnUninterruptedRun) {
    const fs::path dir = testScratchDir("resume-kill");
    const fs::path reference = dir / "reference";
    const auto start = std::chrono::steady_clock::now();
    const CommandResult r = runQsgi(renderArguments() + " --out " + reference.string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const double duration = secondsSince(start);

    // The kill moment is drawn inside the frames, not inside the launch: wait until a random frame
    // (0..kFrames-4) is on disk, then up to one more frame's time. Timing from launch alone missed
    // every run on a machine whose first (reference) run was slowed by a cold start.
    std::mt19937 random{std::random_device{}()};
    std::uniform_int_distribution<int> frameOnDisk(0, kFrames - 4);
    std::uniform_real_distribution<double> withinFrame(0.0, 1.0);
    const double frameSeconds = duration / kFrames;
    int interrupted = 0;
    for (int attempt = 0; attempt < 4; ++attempt) {
        const int frame = frameOnDisk(random);
        const double seconds = withinFrame(random) * frameSeconds;
        SCOPED_TRACE("SIGKILL " + std::to_string(seconds) + " s after frame " + std::to_string(frame) + " was written");
        const fs::path out = dir / ("killed" + std::to_string(attempt));
        char written[32];
        std::snprintf(written, sizeof written, "frame_%04d.ply", frame);
        const SignalledRun killed =
            runAndSignal(renderArguments() + " --out " + out.string(), "9", seconds, dir, out / written);
        if (killed.exitCode != 0) ++interrupted;
        // What a kill leaves: timing.json lists only frames whose every file is complete.
        if (fs::exists(out / "timing.json"))
            for (int frame : loggedFrames(out))
                for (const char* ext : {"ply", "exr", "png"}) {
                    char name[32];
                    std::snprintf(name, sizeof name, "frame_%04d.%s", frame, ext);
                    EXPECT_TRUE(fs::exists(out / name)) << name << " is logged but absent";
                }
        // Resumed with another thread count: the fingerprint leaves threads out.
        const CommandResult resumed = runQsgi(renderArguments() + " --threads 1 --resume --out " + out.string());
        ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
        expectSameFrameFiles(reference, out);
        EXPECT_EQ(loggedFrames(out).size(), size_t(kFrames));
        for (const auto& e : fs::directory_iterator(out))
            EXPECT_EQ(e.path().string().find(".qsgi-tmp"), std::string::npos) << "a temporary file was left: " << e.path();
    }
    EXPECT_GT(interrupted, 0) << "no kill landed inside the run; the test checked nothing";
}

TEST(Resume, SigintAndSigtermStopAfterTheCurrentFrameWithAConsistentFolder) {
    const fs::path dir = testScratchDir("resume-signal");
    const fs::path reference = dir / "reference";
    ASSERT_EQ(runQsgi(renderArguments() + " --out " + reference.string()).exitCode, 0);
    for (const char* signal : {"INT", "TERM"}) {
        SCOPED_TRACE(signal);
        const fs::path out = dir / signal;
        // Signalled just after frame 1 is on disk, well before the last of the frames, so the stop
        // lands inside the run on any machine speed.
        const SignalledRun stopped =
            runAndSignal(renderArguments() + " --out " + out.string(), signal, 0.0, dir, out / "frame_0001.ply");
        ASSERT_EQ(stopped.exitCode, std::string(signal) == "INT" ? 130 : 143) << stopped.output;
        EXPECT_NE(stopped.output.find("--resume"), std::string::npos) << stopped.output;
        EXPECT_NE(stopped.output.find(std::string("SIG") + signal), std::string::npos) << stopped.output;
        // Consistent: the log lists exactly the frames on disk, 0..n-1, with all their files.
        const std::vector<int> logged = loggedFrames(out);
        ASSERT_FALSE(logged.empty());
        for (size_t i = 0; i < logged.size(); ++i) EXPECT_EQ(logged[i], int(i));
        EXPECT_EQ(frameFiles(out).size(), 3 * logged.size());
        ASSERT_EQ(runQsgi(renderArguments() + " --resume --out " + out.string()).exitCode, 0);
        expectSameFrameFiles(reference, out);
    }
}

TEST(Resume, FolderFromOtherInputsIsRefusedAndLeftUntouched) {
    const fs::path dir = testScratchDir("resume-refuse");
    const fs::path out = dir / "out";
    const std::string few = " --frames 0:2 --photons 20000 --width 40 --height 30 --estimator detp --quiet" + std::string(kCheapSecondPass);
    const fs::path cornell = sourceDir() / "data" / "cornell";
    const std::string scene = (cornell / "cornell.gltf").string() + " --animation " + (cornell / "animation.json").string();
    ASSERT_EQ(runQsgi("render " + scene + few + " --out " + out.string()).exitCode, 0);
    const std::string before = readFileBytes(out / "frame_0001.ply") + readFileBytes(out / "timing.json");
    for (const char* change : {" --seed 7", " --estimator photon-map", " --radius 0.02", " --spp 2", " --png",
                               " --sampler random", " --qmc-bounces 1", " --gather 8", " --direct-samples 2",
                               " --direct photons --gather 0"}) {
        SCOPED_TRACE(change);
        const CommandResult r = runQsgi("render " + scene + few + change + " --resume --out " + out.string());
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find("other inputs or settings"), std::string::npos) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        EXPECT_EQ(readFileBytes(out / "frame_0001.ply") + readFileBytes(out / "timing.json"), before);
    }
    // The same inputs with another update strategy, or a setting DETP does not read (the photon
    // map's k): nothing left to do, nothing rewritten.
    for (const char* change : {" --full-recompute", " --k 7"}) {
        SCOPED_TRACE(change);
        const CommandResult same = runQsgi("render " + scene + few + change + " --resume --out " + out.string());
        EXPECT_EQ(same.exitCode, 0) << same.output;
        EXPECT_EQ(readFileBytes(out / "frame_0001.ply") + readFileBytes(out / "timing.json"), before);
    }
    // Frame files without a log are not ours to continue.
    fs::remove(out / "timing.json");
    const CommandResult orphan = runQsgi("render " + scene + few + " --resume --out " + out.string());
    EXPECT_EQ(orphan.exitCode, 2) << orphan.output;
    EXPECT_NE(orphan.output.find("no timing.json"), std::string::npos) << orphan.output;
}
