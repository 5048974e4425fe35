// The qsgi executable end to end: determinism of the bytes it writes, and bad input giving one
// clear message, exit code 2 and nothing written (docs/design.md §8).
#include <gtest/gtest.h>

#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include "output/image_compare.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

std::string cornell() { return (sourceDir() / "data/cornell/cornell.gltf").string(); }
std::string cornellAnimation() { return (sourceDir() / "data/cornell/animation.json").string(); }

void writeText(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// Runs a command that must fail on bad input: exit 2, the message names `mention`, no output folder.
void expectBadInput(const std::string& args, const std::string& mention, const fs::path& out) {
    const CommandResult r = runQsgi(args + " --out " + out.string());
    EXPECT_EQ(r.exitCode, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(mention), std::string::npos) << "message should name '" << mention << "':\n" << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "one line expected:\n" << r.output;
    EXPECT_FALSE(fs::exists(out)) << "bad input must write nothing: " << args;
}

// Runs qsgi with its output on a pseudo-terminal, as a user's terminal is: everything it wrote.
CommandResult runQsgiOnTerminal(const std::vector<std::string>& arguments) {
    std::vector<std::string> words{QSGI_CLI};
    words.insert(words.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& w : words) argv.push_back(w.data());
    argv.push_back(nullptr);
    int terminal = -1;
    const pid_t child = forkpty(&terminal, nullptr, nullptr, nullptr);
    if (child < 0) return {-1, "forkpty failed"};
    if (child == 0) {
        execv(argv[0], argv.data());
        _exit(127);
    }
    CommandResult r{-1, ""};
    char buffer[4096];
    for (;;) {
        const ssize_t n = read(terminal, buffer, sizeof buffer);
        if (n > 0) r.output.append(buffer, size_t(n));
        else if (n < 0 && errno == EINTR) continue;
        else break;  // EIO once the child has closed the terminal
    }
    close(terminal);
    int status = 0;
    waitpid(child, &status, 0);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

}  // namespace

// What the README promises: on a terminal a status line (frame i of N, the stage, a bar while
// tracing) redrawn in place; a summary line at the end on a terminal or not; neither with --quiet,
// and no status line when stderr is not a terminal.
// Every new stage is drawn when it starts and "left" once a frame is done (cli/run_display.cpp),
// so what is looked for appears however short the stages are: the second pass is the cheap one.
TEST(Cli, ProgressIsDrawnOnATerminalOnlyAndEveryRunEndsWithASummary) {
    const fs::path dir = testScratchDir("progress");
    const std::vector<std::string> args{"render", cornell(), "--animation", cornellAnimation(), "--frames", "0:2",
                                        "--photons", "20000", "--no-exr", "--gather", "16", "--direct-samples", "4"};
    std::vector<std::string> onTerminal = args;
    onTerminal.insert(onTerminal.end(), {"--out", (dir / "terminal").string()});
    const CommandResult t = runQsgiOnTerminal(onTerminal);
    ASSERT_EQ(t.exitCode, 0) << t.output;
    for (const char* expected : {"qsgi: frame 1/3", "qsgi: frame 3/3", "tracing [", "retracing", "elapsed", "left", "\r",
                                 "qsgi: wrote 3 frames to "})
        EXPECT_NE(t.output.find(expected), std::string::npos) << "missing '" << expected << "' in:\n" << t.output;

    std::string common;
    for (const std::string& a : args) common += " " + a;
    const CommandResult file = runQsgi(common + " --out " + (dir / "file").string());
    ASSERT_EQ(file.exitCode, 0) << file.output;
    EXPECT_EQ(file.output.find('\r'), std::string::npos) << file.output;
    EXPECT_EQ(file.output.find("frame 1/3"), std::string::npos) << file.output;
    EXPECT_NE(file.output.find("qsgi: wrote 3 frames to " + (dir / "file").string() + " in "), std::string::npos) << file.output;
    EXPECT_EQ(std::count(file.output.begin(), file.output.end(), '\n'), 1) << file.output;

    std::vector<std::string> quiet = onTerminal;
    quiet.back() = (dir / "quiet").string();
    quiet.push_back("--quiet");
    const CommandResult q = runQsgiOnTerminal(quiet);
    ASSERT_EQ(q.exitCode, 0) << q.output;
    EXPECT_TRUE(q.output.empty()) << q.output;
}

TEST(Cli, OutputBytesAreIdenticalForOneAndTwoThreadsAndRepeatedRuns) {
    const fs::path dir = testScratchDir("determinism");
    const std::string common = cornell() + " --animation " + cornellAnimation() +
                               " --frames 0:2 --photons 60000 --seed 3 --width 160 --height 120 --spp 2 --png" + kCheapSecondPass;
    for (const char* run : {"t1", "t2", "t2again"}) {
        const std::string threads = std::string(run) == "t1" ? "1" : "2";
        const CommandResult r = runQsgi("render " + common + " --threads " + threads + " --out " + (fs::path(dir) / run).string());
        ASSERT_EQ(r.exitCode, 0) << r.output;
    }
    for (int f = 0; f <= 2; ++f)
      for (const char* ext : {".ply", ".exr", ".png"}) {
        const std::string name = "frame_000" + std::to_string(f) + ext;
        const std::string a = readFileBytes(fs::path(dir) / "t1" / name);
        ASSERT_GT(a.size(), 1000u) << name;
        EXPECT_EQ(a, readFileBytes(fs::path(dir) / "t2" / name)) << name << " differs between 1 and 2 threads";
        EXPECT_EQ(a, readFileBytes(fs::path(dir) / "t2again" / name)) << name << " differs between runs";
    }
    // The block moves, so frames differ.
    EXPECT_NE(readFileBytes(fs::path(dir) / "t1/frame_0000.ply"), readFileBytes(fs::path(dir) / "t1/frame_0002.ply"));
    EXPECT_TRUE(fs::exists(fs::path(dir) / "t1/timing.json"));
}

TEST(Cli, RenderWritesOnePlyPerFrameAndATimingLog) {
    const fs::path dir = testScratchDir("frames");
    const CommandResult r = runQsgi("render " + cornell() + " --animation " + cornellAnimation() +
                                    " --frames 5:7 --photons 20000 --quiet" + kCheapSecondPass + " --out " + dir.string());
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_TRUE(r.output.empty()) << r.output;
    for (int f : {5, 6, 7}) EXPECT_TRUE(fs::exists(dir / ("frame_000" + std::to_string(f) + ".ply")));
    EXPECT_FALSE(fs::exists(dir / "frame_0004.ply"));
    EXPECT_FALSE(fs::exists(dir / "frame_0008.ply"));
    const std::string timing = readFileBytes(dir / "timing.json");
    EXPECT_NE(timing.find("\"photon_simulation\""), std::string::npos);
    EXPECT_NE(timing.find("\"segments\""), std::string::npos);
    for (const auto& e : fs::directory_iterator(dir)) EXPECT_EQ(e.path().string().find(".qsgi-tmp"), std::string::npos);
}

TEST(Cli, HelpAndVersion) {
    EXPECT_EQ(runQsgi("--help").exitCode, 0);
    const CommandResult v = runQsgi("--version");
    EXPECT_EQ(v.exitCode, 0);
    EXPECT_NE(v.output.find("qsgi"), std::string::npos);
}

TEST(Cli, BadInputGivesOneClearMessageExitCodeTwoAndWritesNothing) {
    const fs::path dir = testScratchDir("badinput");
    const fs::path out = dir / "out";

    expectBadInput("render " + (dir / "missing.gltf").string(), "missing.gltf", out);

    writeText(dir / "malformed.gltf", "{ \"asset\": { \"version\": \"2.0\" }, \"scenes\": [ ");
    expectBadInput("render " + (dir / "malformed.gltf").string(), "malformed.gltf", out);

    // A .gltf whose buffer file is missing.
    writeText(dir / "nobin.gltf",
              R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
                  "meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
                  "buffers":[{"uri":"absent.bin","byteLength":36}],
                  "bufferViews":[{"buffer":0,"byteLength":36}],
                  "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}]})");
    expectBadInput("render " + (dir / "nobin.gltf").string(), "nobin.gltf", out);

    testscenes::writeQuadGltf((dir / "dark.gltf").string(), false);
    expectBadInput("render " + (dir / "dark.gltf").string(), "no lights", out);

    testscenes::writeQuadGltf((dir / "lit.gltf").string(), true);
    const std::string lit = (dir / "lit.gltf").string();
    const CommandResult ok = runQsgi("render " + lit + " --photons 100 --out " + (dir / "ok").string());
    ASSERT_EQ(ok.exitCode, 0) << ok.output;
    // A lone emitting quad sends every photon into the void: the user is told.
    EXPECT_NE(ok.output.find("100% of the photons hit no geometry"), std::string::npos) << ok.output;

    writeText(dir / "unknown.json",
              R"({"format":"qsgi-animation","version":1,"frames":[{"frame":0,"nodes":{"Nope":{"translation":[0,0,0]}}}]})");
    expectBadInput("render " + lit + " --animation " + (dir / "unknown.json").string(), "Nope", out);

    writeText(dir / "inf.json",
              R"({"format":"qsgi-animation","version":1,"frames":[{"frame":0,"nodes":{"Quad":{"translation":[0,1e999,0]}}}]})");
    expectBadInput("render " + lit + " --animation " + (dir / "inf.json").string(), "inf.json", out);

    writeText(dir / "nan.json",
              R"({"format":"qsgi-animation","version":1,"frames":[{"frame":0,"nodes":{"Quad":{"translation":[0,NaN,0]}}}]})");
    expectBadInput("render " + lit + " --animation " + (dir / "nan.json").string(), "nan.json", out);

    writeText(dir / "order.json",
              R"({"format":"qsgi-animation","version":1,"frames":[{"frame":1},{"frame":1}]})");
    expectBadInput("render " + lit + " --animation " + (dir / "order.json").string(), "duplicated", out);


    expectBadInput("render " + lit + " --photons 0", "--photons", out);
    expectBadInput("render " + lit + " --photons -5", "--photons", out);
    expectBadInput("render " + lit + " --frames 3:1", "frames", out);
    // Values out of range or unparsable: refused with one line, never clamped or wrapped.
    expectBadInput("render " + lit + " --photons abc", "--photons", out);
    expectBadInput("render " + lit + " --photons 8589934592", "2^32", out);
    expectBadInput("render " + lit + " --bogus-option", "--bogus-option", out);
    expectBadInput("render " + lit + " --threads 5000", "0..1024", out);
    expectBadInput("render " + lit + " --k 0", "--k", out);
    expectBadInput("render " + lit + " --k 99999999999", "--k", out);
    expectBadInput("render " + lit + " --seed -1", "--seed", out);
    expectBadInput("render " + lit + " --radius nan", "--radius", out);
    expectBadInput("render " + lit + " --radius 1e40", "--radius", out);
    expectBadInput("render " + lit + " --frames 0:99999999999", "frames", out);
    expectBadInput("render " + lit + " --camera 99999999999", "--camera", out);

    // An output folder that cannot be created: its parent is a regular file.
    writeText(dir / "file", "x");
    const CommandResult r = runQsgi("render " + lit + " --photons 100 --out " + (dir / "file" / "sub").string());
    EXPECT_EQ(r.exitCode, 2) << r.output;
    EXPECT_NE(r.output.find("file/sub"), std::string::npos) << r.output;
}

TEST(Cli, ImageOptionsAreCheckedBeforeAnythingIsWritten) {
    const fs::path dir = testScratchDir("badimage");
    const fs::path out = dir / "out";
    expectBadInput("render " + cornell() + " --camera 5", "--camera 5", out);
    expectBadInput("render " + cornell() + " --camera -3", "--camera", out);
    expectBadInput("render " + cornell() + " --width 0", "--width", out);
    expectBadInput("render " + cornell() + " --height 20000", "16384", out);
    expectBadInput("render " + cornell() + " --spp 0", "--spp", out);
    expectBadInput("render " + cornell() + " --exposure -1", "--exposure", out);
}

// A run killed mid-frame leaves only complete files under the final names: every frame_NNNN.exr
// that exists opens and holds the whole image (the writer renames a finished temporary file).
TEST(Cli, AnInterruptedRunNeverLeavesATruncatedExr) {
    const fs::path out = testScratchDir("interrupted");
    const std::string command = std::string(QSGI_CLI) + " render " + cornell() + " --animation " + cornellAnimation() +
                                " --photons 20000 --width 640 --height 480 --quiet --out " + out.string() +
                                // Killed 0.2 s after frame 0's EXR is in place (a fixed delay from
                                // launch was too short under ASan): later frames are mid-write.
                                " & pid=$!; for i in $(seq 6000); do [ -e " + (out / "frame_0000.exr").string() +
                                " ] && break; sleep 0.01; done; sleep 0.2; kill -9 $pid; wait $pid 2>/dev/null; true";
    ASSERT_EQ(std::system(command.c_str()), 0);
    int complete = 0;
    for (const auto& e : fs::directory_iterator(out)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("frame_", 0) != 0 || e.path().extension() != ".exr" || name.find(".qsgi-tmp") != std::string::npos) continue;
        const auto self = qsgi::compareImages(e.path(), e.path(), qsgi::ImageTolerance{});
        EXPECT_TRUE(self.readable) << name << ": " << self.problem;
        ++complete;
    }
    EXPECT_GT(complete, 0) << "frame 0 was never written";
}

// Every estimator end to end: PLY, EXR with the estimator and radius in its metadata, and the
// same choices recorded in timing.json.
TEST(Cli, EveryEstimatorRendersEndToEnd) {
    for (const char* estimator : {"detp", "photon-map", "impact-count"}) {
        const fs::path out = testScratchDir(std::string("estimator_") + estimator);
        const CommandResult r = runQsgi("render " + cornell() + " --estimator " + estimator +
                                        " --radius 0.07 --k 30 --photons 20000 --width 80 --height 60" + kCheapSecondPass + " --out " + out.string());
        ASSERT_EQ(r.exitCode, 0) << estimator << "\n" << r.output;
        EXPECT_TRUE(fs::exists(out / "frame_0000.ply"));
        const std::string info = readFileBytes(out / "frame_0000.exr");
        EXPECT_NE(info.find(estimator), std::string::npos) << "EXR metadata should name " << estimator;
        const std::string timing = readFileBytes(out / "timing.json");
        EXPECT_NE(timing.find(std::string("\"estimator\": \"") + estimator + "\""), std::string::npos) << timing;
        if (std::string(estimator) != "impact-count") {
            EXPECT_NE(timing.find("\"radius\": 0.07"), std::string::npos) << timing;
        }
        EXPECT_NE(timing.find("\"sampler\": \"sobol\""), std::string::npos) << timing;
        EXPECT_NE(timing.find("\"qmc_bounces\": 2"), std::string::npos) << timing;
    }
    const fs::path out = fs::path(testScratchDir("estimator_bad")) / "out";
    expectBadInput("render " + cornell() + " --estimator magic", "magic", out);
    expectBadInput("render " + cornell() + " --estimator detp --radius -1", "--radius", out);
    expectBadInput("render " + cornell() + " --estimator detp --detp-index octree", "octree", out);
    expectBadInput("render " + cornell() + " --estimator photon-map --k 0", "--k", out);
    expectBadInput("render " + cornell() + " --sampler halton", "halton", out);
    expectBadInput("render " + cornell() + " --qmc-bounces 33", "--qmc-bounces", out);
    const fs::path fewBounces = fs::path(testScratchDir("estimator_bad_config")) / "few_bounces.json";
    writeText(fewBounces, R"({"max_bounces": 4})");
    expectBadInput("render " + cornell() + " --qmc-bounces 5 --config " + fewBounces.string(), "qmc_bounces", out);
    // The default K (2) is capped at max_bounces, not refused.
    const fs::path oneBounce = fs::path(testScratchDir("estimator_bad_config")) / "one_bounce.json";
    writeText(oneBounce, R"({"max_bounces": 1})");
    const fs::path capped = fs::path(testScratchDir("estimator_capped_k")) / "out";
    const CommandResult r = runQsgi("render " + cornell() + " --photons 2000 --no-exr --quiet --config " + oneBounce.string() +
                                    " --out " + capped.string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(readFileBytes(capped / "timing.json").find("\"qmc_bounces\": 1"), std::string::npos);
}

// The incremental update writes the bytes --full-recompute writes, for each estimator and rule on
// data/cornell (timing.json aside: it records how each frame was computed).
TEST(Cli, IncrementalRunWritesTheBytesOfAFullRecomputation) {
    const fs::path dir = testScratchDir("incremental");
    // With exact direct light and a gather (fewer rays than the defaults': the update's work is
    // the same kind, re-cast rays and kept hits). Frames 0 to 2: frame 1 is updated from a frame
    // computed from scratch, frame 2 from an updated one; the block moves by the same step each
    // frame (data/cornell/animation.json), so a further frame would take frame 2's path again.
    const std::string common = cornell() + " --animation " + cornellAnimation() +
                               " --frames 0:2 --photons 30000 --quiet --no-exr" + kCheapSecondPass;
    std::vector<std::string> estimators = {"impact-count", "photon-map", "detp --detp-boundary clip",
                                           "detp --detp-boundary linear", "detp --detp-boundary paper"};
    // Under the sanitizers two of them: every estimator's update is checked in-process there
    // (Incremental.EveryFrameEqualsFullRecomputationForEveryEstimator); what this test adds, the
    // render job's incremental frames end to end, is the same code for all five.
    if (kSanitized) estimators = {"photon-map", "detp --detp-boundary linear"};
    for (const std::string& estimator : estimators) {
        SCOPED_TRACE(estimator);
        const fs::path inc = dir / "inc", full = dir / "full";
        fs::remove_all(inc);
        fs::remove_all(full);
        ASSERT_EQ(runQsgi("render " + common + " --estimator " + estimator + " --out " + inc.string()).exitCode, 0);
        const CommandResult r = runQsgi("render " + common + " --estimator " + estimator + " --full-recompute --out " + full.string());
        ASSERT_EQ(r.exitCode, 0) << r.output;
        for (int f = 0; f <= 2; ++f) {
            const std::string name = "frame_000" + std::to_string(f) + ".ply";
            const std::string a = readFileBytes(inc / name);
            ASSERT_GT(a.size(), 1000u);
            EXPECT_EQ(a, readFileBytes(full / name)) << name;
        }
        EXPECT_NE(readFileBytes(inc / "timing.json").find("\"full_recompute\": false"), std::string::npos);
        EXPECT_NE(readFileBytes(full / "timing.json").find("\"full_recompute\": true"), std::string::npos);
    }
}

// A run that starts mid-animation rebuilds the state at its first frame from scratch and takes
// its previews' tonemap from frame 0, so it writes the sequential run's bytes (PLY colours, EXR, PNG).
TEST(Cli, FrameRangeStartingMidAnimationWritesTheSequentialBytes) {
    const fs::path dir = testScratchDir("midrange");
    const std::string common = cornell() + " --animation " + cornellAnimation() +
                               " --photons 30000 --estimator detp --width 96 --height 72 --png --quiet" + kCheapSecondPass;
    ASSERT_EQ(runQsgi("render " + common + " --frames 0:5 --out " + (dir / "all").string()).exitCode, 0);
    ASSERT_EQ(runQsgi("render " + common + " --frames 3:5 --out " + (dir / "late").string()).exitCode, 0);
    for (int f = 3; f <= 5; ++f)
        for (const char* ext : {".ply", ".exr", ".png"}) {
            const std::string name = "frame_000" + std::to_string(f) + ext;
            const std::string a = readFileBytes(dir / "all" / name);
            ASSERT_GT(a.size(), 500u) << name;
            EXPECT_EQ(a, readFileBytes(dir / "late" / name)) << name;
        }
    EXPECT_FALSE(fs::exists(dir / "late/frame_0002.ply"));
}

// A mistyped flag is named with the nearest known one, as a config's unknown key is; a mistyped
// subcommand likewise; and the top-level help points to each subcommand's own.
TEST(Cli, AMistypedFlagOrSubcommandNamesTheNearestOne) {
    const fs::path out = fs::path(testScratchDir("typo")) / "out";
    const CommandResult flag = runQsgi("render " + cornell() + " --photon 1000 --out " + out.string());
    EXPECT_EQ(flag.exitCode, 2) << flag.output;
    EXPECT_EQ(std::count(flag.output.begin(), flag.output.end(), '\n'), 1) << flag.output;
    EXPECT_NE(flag.output.find("unknown flag --photon"), std::string::npos) << flag.output;
    EXPECT_NE(flag.output.find("did you mean \"--photons\"?"), std::string::npos) << flag.output;
    EXPECT_FALSE(fs::exists(out));
    // With an = and on inspect, which takes the same options.
    const CommandResult inspect = runQsgi("inspect " + cornell() + " --estimater=detp");
    EXPECT_EQ(inspect.exitCode, 2) << inspect.output;
    EXPECT_NE(inspect.output.find("did you mean \"--estimator\"?"), std::string::npos) << inspect.output;
    // A negative number is a value, not a flag: the option's own rule speaks.
    const CommandResult negative = runQsgi("render " + cornell() + " --radius -1 --out " + out.string());
    EXPECT_EQ(negative.exitCode, 2) << negative.output;
    EXPECT_EQ(negative.output.find("unknown flag"), std::string::npos) << negative.output;
    const CommandResult verb = runQsgi("rendr " + cornell());
    EXPECT_EQ(verb.exitCode, 2) << verb.output;
    EXPECT_NE(verb.output.find("did you mean \"render\"?"), std::string::npos) << verb.output;
    const CommandResult help = runQsgi("--help");
    EXPECT_EQ(help.exitCode, 0);
    for (const char* sub : {"qsgi render --help", "qsgi inspect --help", "qsgi compare --help"})
        EXPECT_NE(help.output.find(sub), std::string::npos) << help.output;
}

// A glTF file's own animations are announced when the run does not play them: in the message that
// refuses a frame range and in the end-of-run note, with their frame counts and the flag.
TEST(Cli, AnimationsTheFileCarriesAreAnnouncedWhenNotPlayed) {
    const fs::path out = fs::path(testScratchDir("unplayed")) / "out";
    const std::string walker = (sourceDir() / "data/walker/walker.gltf").string();
    const CommandResult range = runQsgi("render " + walker + " --frames 0:10 --out " + out.string());
    EXPECT_EQ(range.exitCode, 2) << range.output;
    for (const char* words : {"last frame, 0", "'Walk', 97 frames at 24 fps", "--animation gltf"})
        EXPECT_NE(range.output.find(words), std::string::npos) << words << ": " << range.output;
    const CommandResult still = runQsgi("render " + walker + " --fps 10 --photons 5000 --no-exr --out " + out.string());
    ASSERT_EQ(still.exitCode, 0) << still.output;
    EXPECT_NE(still.output.find("qsgi: note: " + walker + ": the scene file has 1 animation: 'Walk', 41 frames at 10 fps; "
                                "--animation gltf plays it"),
              std::string::npos)
        << still.output;
    // Played, nothing to announce.
    const CommandResult played = runQsgi("render " + walker + " --animation gltf --frames 0:0 --photons 5000 --no-exr --out " +
                                         (out.string() + "-played"));
    ASSERT_EQ(played.exitCode, 0) << played.output;
    EXPECT_EQ(played.output.find("note:"), std::string::npos) << played.output;
}

// The status line lives through a long stage: it is redrawn with a moving clock and a growing
// bar. `stage` as the line names it, `timing` the stage's seconds in timing.json.
static void expectTheStatusLineMoves(const std::vector<std::string>& arguments, const char* stage, const char* timing) {
    SCOPED_TRACE(stage);
    const fs::path out = fs::path(testScratchDir(std::string("status-") + stage)) / "out";
    std::vector<std::string> all = arguments;
    all.insert(all.end(), {"--threads", "1", "--no-exr", "--out", out.string()});
    const CommandResult t = runQsgiOnTerminal(all);
    ASSERT_EQ(t.exitCode, 0) << t.output;
    std::set<std::string> clocks, bars;
    std::istringstream drawings(t.output);
    const std::string marker = std::string("  ") + stage + " [";
    for (std::string drawn; std::getline(drawings, drawn, '\r');) {
        const size_t at = drawn.find(marker);
        if (at == std::string::npos) continue;
        const size_t elapsed = drawn.find(" elapsed");
        ASSERT_NE(elapsed, std::string::npos) << drawn;
        clocks.insert(drawn.substr(elapsed - 4, 4));
        bars.insert(drawn.substr(at));
    }
    // How long the stage took decides what must have been seen: the clock crosses a whole second
    // at least floor(s) times, and the ticker (four times a second) redraws the bar at least
    // twice a second on any machine.
    const double seconds = nlohmann::json::parse(readFileBytes(out / "timing.json"))["frames"][0][timing].get<double>();
    EXPECT_GE(double(clocks.size()), std::floor(seconds)) << seconds << " s of " << stage << "; the clock did not move:\n" << t.output;
    EXPECT_GE(double(bars.size()), std::floor(2 * seconds)) << seconds << " s of " << stage << "; the bar did not move:\n" << t.output;
    EXPECT_GE(bars.size(), 1u) << t.output;
}

// Disc regions (2 s here, one thread, a wide radius) and the final gather (about as long: 512 rays
// from each of data/cornell's 21,636 vertices, one thread).
TEST(Cli, TheStatusLineMovesDuringLongRegionsAndGatherStages) {
    expectTheStatusLineMoves({"render", cornell(), "--estimator", "detp", "--radius", "0.3", "--photons", "1000",
                              "--direct", "photons", "--gather", "0"},
                             "regions", "disc_regions_s");
    expectTheStatusLineMoves({"render", cornell(), "--photons", "1000", "--gather", "512"}, "gathering", "gather_s");
}
