// Hostile folders and disks (issue 32): nothing is written through a name qsgi did not create,
// a resumed folder is verified rather than trusted, a full disk ends cleanly and --resume then
// completes the run byte for byte, one run holds a folder at a time, and names are bytes.
// The full disk and the unlockable file system come from tests/support/fail_writes.c, preloaded
// into qsgi, so these run everywhere; a real small tmpfs is tried as well where the tests run as
// root.
#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <set>

#include "test_support.h"

namespace fs = std::filesystem;

namespace {

// Six frames of data/cornell with PLY, EXR and PNG, small and few photons: about a second.
std::string renderArguments(const std::string& frames = "0:5") {
    const fs::path cornell = sourceDir() / "data" / "cornell";
    return "render " + (cornell / "cornell.gltf").string() + " --animation " + (cornell / "animation.json").string() +
           " --frames " + frames + " --photons 20000 --width 40 --height 30 --png" + kCheapSecondPass;
}

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// qsgi with the failing-disk library preloaded and `environment` ("QSGI_FAIL_WRITES_AFTER=N").
CommandResult runPreloaded(const std::string& environment, const std::string& arguments) {
    // Under AddressSanitizer a preloaded library comes before its runtime, which it otherwise refuses.
    const std::string asan = kSanitized ? "ASAN_OPTIONS=\"${ASAN_OPTIONS}:verify_asan_link_order=0\" " : "";
    return runCommand(asan + "LD_PRELOAD=" + QSGI_FAIL_WRITES + " " + environment + " " + QSGI_CLI + " " + arguments);
}

void expectSameFrameFiles(const fs::path& reference, const fs::path& other) {
    const std::set<std::string> names = frameFiles(reference);
    EXPECT_EQ(frameFiles(other), names);
    for (const std::string& name : names) EXPECT_EQ(readFileBytes(reference / name), readFileBytes(other / name)) << name;
}

// The folder is consistent: timing.json lists exactly the frames whose files are on disk, each
// with all three files, and no temporary is left.
void expectConsistent(const fs::path& out) {
    std::set<std::string> expected;
    for (int frame : loggedFrames(out))
        for (const char* ext : {"ply", "exr", "png"}) {
            char name[32];
            std::snprintf(name, sizeof name, "frame_%04d.%s", frame, ext);
            expected.insert(name);
        }
    EXPECT_EQ(frameFiles(out), expected);
    for (const auto& e : fs::directory_iterator(out))
        EXPECT_EQ(e.path().filename().string().find(".qsgi-tmp"), std::string::npos) << "a temporary was left: " << e.path();
}

// A reference run of renderArguments(frames) into `dir`/reference, made once per test.
fs::path referenceRun(const fs::path& dir, const std::string& frames = "0:5") {
    const fs::path reference = dir / "reference";
    const CommandResult r = runQsgi(renderArguments(frames) + " --quiet --out " + quoted(reference));
    EXPECT_EQ(r.exitCode, 0) << r.output;
    return reference;
}

void copyFolder(const fs::path& from, const fs::path& to) {
    fs::create_directories(to);
    for (const auto& e : fs::directory_iterator(from)) fs::copy_file(e.path(), to / e.path().filename());
}

}  // namespace

TEST(OutputSafety, ALinkPlantedAtAnyNameQsgiWritesIsReplacedNeverWrittenThrough) {
    const fs::path dir = testScratchDir("safety-links");
    const fs::path victim = dir / "victim.txt";
    const std::string precious = "a file its owner never gave qsgi\n";
    {
        std::ofstream(victim) << precious;
    }
    const std::vector<std::string> frameNames = {"frame_0000.ply", "frame_0000.exr", "frame_0000.png",
                                                 "frame_0001.ply", "frame_0001.exr", "frame_0001.png"};
    // Links at the lock's name and at every temporary a two-frame run makes, for the pid the
    // shell hands to qsgi by exec: the probe's, each frame file's and timing.json's.
    auto planted = [&](const fs::path& out) {
        fs::create_directories(out);
        fs::create_symlink(victim, out / ".qsgi-lock");
        std::string plant;
        for (int n = 0; n < 16; ++n) {
            std::vector<std::string> names = frameNames;
            names.insert(names.end(), {"write-test", "timing.json"});
            for (const std::string& name : names)
                plant += "ln -s " + quoted(victim) + " " + quoted(out) + "/.qsgi-tmp.\\$\\$." + std::to_string(n) + "." + name + "; ";
        }
        return plant;
    };
    const std::string asan = kSanitized ? "ASAN_OPTIONS=\\\"\\${ASAN_OPTIONS}:verify_asan_link_order=0\\\" " : "";
    // With the lock, stale temporaries (the planted links among them) are unlinked before the
    // run; on a file system that cannot lock they stay, and exclusive creation steps past each.
    for (const char* environment : {"", "QSGI_FAIL_FLOCK=1"}) {
        SCOPED_TRACE(*environment ? environment : "with the lock");
        const fs::path out = dir / (*environment ? "unlocked" : "locked");
        const CommandResult r = runCommand("sh -c \"" + planted(out) + " exec env " + asan + "LD_PRELOAD=" + QSGI_FAIL_WRITES +
                                           " " + environment + " " + QSGI_CLI + " " + renderArguments("0:1") + " --out " +
                                           quoted(out) + "\"");
        ASSERT_EQ(r.exitCode, 0) << r.output;
        EXPECT_EQ(readFileBytes(victim), precious);
        EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(out / ".qsgi-lock")));
        if (*environment) {
            EXPECT_NE(r.output.find("cannot lock"), std::string::npos) << r.output;
        }
        // The run is whole: --resume verifies every frame and has nothing to do.
        const CommandResult again = runQsgi(renderArguments("0:1") + " --resume --out " + quoted(out));
        EXPECT_EQ(again.exitCode, 0) << again.output;
        EXPECT_NE(again.output.find("already complete"), std::string::npos) << again.output;
    }
    // Links at the frame names of a run's own folder: rendering the frames again replaces them.
    const fs::path out = dir / "locked";
    for (const std::string& name : frameNames) {
        fs::remove(out / name);
        fs::create_symlink(victim, out / name);
    }
    const CommandResult again = runQsgi(renderArguments("0:1") + " --quiet --out " + quoted(out));
    ASSERT_EQ(again.exitCode, 0) << again.output;
    EXPECT_EQ(readFileBytes(victim), precious);
    for (const std::string& name : frameNames) EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(out / name))) << name;
    expectConsistent(out);

    // Links at frame names or at timing.json in a folder of no run: nothing says they are
    // qsgi's, so the render is refused; --overwrite unlinks the links, never what they point to.
    for (const char* name : {"frame_0000.exr", "timing.json"}) {
        SCOPED_TRACE(name);
        const fs::path foreign = dir / ("foreign-" + std::string(name));
        fs::create_directories(foreign);
        fs::create_symlink(victim, foreign / name);
        const CommandResult refused = runQsgi(renderArguments("0:0") + " --out " + quoted(foreign));
        EXPECT_EQ(refused.exitCode, 2) << refused.output;
        const CommandResult replaced = runQsgi(renderArguments("0:0") + " --overwrite --quiet --out " + quoted(foreign));
        EXPECT_EQ(replaced.exitCode, 0) << replaced.output;
        EXPECT_EQ(readFileBytes(victim), precious);
        EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(foreign / name)));
    }
}

TEST(OutputSafety, ResumeOverCutGarbageAndLinkedFramesGivesTheBytesOfOneCleanRun) {
    const fs::path dir = testScratchDir("safety-resume");
    const fs::path reference = referenceRun(dir);
    const fs::path outside = dir / "outside.png";
    fs::copy_file(reference / "frame_0004.png", outside);

    const fs::path out = dir / "damaged";
    copyFolder(reference, out);
    // Frame 3's PLY cut to a third, frame 2's EXR overwritten by noise of the same size, frame
    // 4's PNG a link to a file outside with the very same bytes (still not a file qsgi wrote).
    const std::string ply = readFileBytes(out / "frame_0003.ply");
    std::ofstream(out / "frame_0003.ply", std::ios::binary | std::ios::trunc) << ply.substr(0, ply.size() / 3);
    std::string noise(readFileBytes(out / "frame_0002.exr").size(), '\0');
    for (size_t i = 0; i < noise.size(); ++i) noise[i] = char((i * 2654435761u) >> 13);
    std::ofstream(out / "frame_0002.exr", std::ios::binary | std::ios::trunc) << noise;
    fs::remove(out / "frame_0004.png");
    fs::create_symlink(outside, out / "frame_0004.png");

    const CommandResult r = runQsgi(renderArguments() + " --resume --out " + quoted(out));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    for (const char* said : {"frame 2 in", "frame_0002.exr has other bytes", "frame 3 in", "frame_0003.ply has",
                             "frame 4 in", "frame_0004.png is a symbolic link"})
        EXPECT_NE(r.output.find(said), std::string::npos) << said << "\n" << r.output;
    expectSameFrameFiles(reference, out);
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(readFileBytes(outside), readFileBytes(reference / "frame_0004.png"));
    expectConsistent(out);

    // A damaged frame outside --frames: its files go, the log forgets it, and the message says
    // how to render it again; the frames asked for are untouched.
    std::ofstream(out / "frame_0005.ply", std::ios::binary | std::ios::trunc) << "not a ply";
    const CommandResult partial = runQsgi(renderArguments("0:3") + " --resume --out " + quoted(out));
    ASSERT_EQ(partial.exitCode, 0) << partial.output;
    EXPECT_NE(partial.output.find("--frames 5:5 --resume"), std::string::npos) << partial.output;
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0, 1, 2, 3, 4}));
    expectConsistent(out);
    const CommandResult whole = runQsgi(renderArguments() + " --resume --quiet --out " + quoted(out));
    ASSERT_EQ(whole.exitCode, 0) << whole.output;
    expectSameFrameFiles(reference, out);
}

TEST(OutputSafety, ADiskThatFillsMidRunEndsCleanlyAndResumeCompletesItByteForByte) {
    const fs::path dir = testScratchDir("safety-full");
    const fs::path reference = referenceRun(dir);
    // The budget runs out inside frame 3's files: frames 0-2 and the log's four versions fit
    // (the final log bounds each), then part of frame 3.
    uintmax_t budget = 5 * fs::file_size(reference / "timing.json") + fs::file_size(reference / "frame_0003.ply") / 2;
    for (int frame = 0; frame < 3; ++frame)
        for (const char* ext : {"ply", "exr", "png"}) {
            char name[32];
            std::snprintf(name, sizeof name, "frame_%04d.%s", frame, ext);
            budget += fs::file_size(reference / name);
        }
    const fs::path out = dir / "full";
    const CommandResult full =
        runPreloaded("QSGI_FAIL_WRITES_AFTER=" + std::to_string(budget), renderArguments() + " --quiet --out " + quoted(out));
    EXPECT_EQ(full.exitCode, 74) << full.output;
    EXPECT_NE(full.output.find("No space left on device"), std::string::npos) << full.output;
    EXPECT_NE(full.output.find(out.string()), std::string::npos) << full.output;
    EXPECT_NE(full.output.find("--resume"), std::string::npos) << full.output;
    EXPECT_EQ(std::count(full.output.begin(), full.output.end(), '\n'), 1) << full.output;
    const std::vector<int> logged = loggedFrames(out);
    EXPECT_GE(logged.size(), 2u);
    EXPECT_LE(logged.size(), 4u);
    expectConsistent(out);
    // Space freed: the run completes, byte for byte.
    const CommandResult resumed = runQsgi(renderArguments() + " --resume --quiet --out " + quoted(out));
    ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
    expectSameFrameFiles(reference, out);
    expectConsistent(out);
    // A disk full before the first frame: the log cannot even be written.
    const CommandResult none = runPreloaded("QSGI_FAIL_WRITES_AFTER=100", renderArguments() + " --out " + quoted(dir / "none"));
    EXPECT_EQ(none.exitCode, 74) << none.output;
    EXPECT_TRUE(frameFiles(dir / "none").empty());
}

TEST(OutputSafety, TheLogNeverListsAFrameThatIsNotWholeWhateverFailsWhere) {
    const fs::path dir = testScratchDir("safety-order");
    const fs::path reference = referenceRun(dir, "0:3");
    // A run of the same inputs over a folder already holding frames 0-3, the disk filling during
    // frame 1: frames 1-3 of the earlier run stay listed and whole (they are rewritten with the
    // same bytes, so a half-rewritten frame is whole too), nothing unlisted stays on disk.
    const fs::path again = dir / "again";
    copyFolder(reference, again);
    uintmax_t budget = 2 * fs::file_size(reference / "timing.json") + fs::file_size(reference / "frame_0001.ply") / 2;
    for (const char* ext : {"ply", "exr", "png"}) budget += fs::file_size(reference / ("frame_0000." + std::string(ext)));
    const CommandResult full =
        runPreloaded("QSGI_FAIL_WRITES_AFTER=" + std::to_string(budget), renderArguments("0:3") + " --quiet --out " + quoted(again));
    EXPECT_EQ(full.exitCode, 74) << full.output;
    EXPECT_EQ(loggedFrames(again), (std::vector<int>{0, 1, 2, 3}));
    expectConsistent(again);
    expectSameFrameFiles(reference, again);

    // A damaged frame outside --frames and a disk that cannot take the new log: the frame stays
    // listed with its files on disk (the log is rewritten before any file is unlinked).
    const fs::path damaged = dir / "damaged";
    copyFolder(reference, damaged);
    std::ofstream(damaged / "frame_0000.png", std::ios::binary | std::ios::trunc) << "cut";
    const CommandResult noSpace =
        runPreloaded("QSGI_FAIL_WRITES_AFTER=100", renderArguments("0:3") + " --frames 2:3 --resume --out " + quoted(damaged));
    EXPECT_EQ(noSpace.exitCode, 74) << noSpace.output;
    EXPECT_EQ(loggedFrames(damaged), (std::vector<int>{0, 1, 2, 3}));
    expectConsistent(damaged);

    // A hand-edited name in the log ("../" out of the folder) is no file of the frame: the frame
    // is computed again, nothing outside is read as if it were.
    nlohmann::json log = nlohmann::json::parse(readFileBytes(damaged / "timing.json"));
    log["frames"][1]["files"][0]["name"] = "frame_0001.d/../../outside.ply";
    std::ofstream(damaged / "timing.json", std::ios::trunc) << log.dump(2);
    const CommandResult edited = runQsgi(renderArguments("0:3") + " --resume --out " + quoted(damaged));
    EXPECT_EQ(edited.exitCode, 0) << edited.output;
    EXPECT_NE(edited.output.find("not a file of this frame"), std::string::npos) << edited.output;
    expectSameFrameFiles(reference, damaged);

    // A folder standing at a frame file's name: refused before any work, even with --overwrite.
    const fs::path blocked = dir / "blocked";
    fs::create_directories(blocked / "frame_0001.exr");
    for (const char* mode : {"", " --overwrite"}) {
        const CommandResult r = runQsgi(renderArguments("0:3") + mode + " --out " + quoted(blocked));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_NE(r.output.find("frame_0001.exr"), std::string::npos) << r.output;
        EXPECT_TRUE(frameFiles(blocked) == std::set<std::string>{"frame_0001.exr"}) << "nothing rendered";
    }
}

TEST(OutputSafety, ARealSmallFileSystemFillsAndResumesWhereTheTestsRunAsRoot) {
    if (::geteuid() != 0) GTEST_SKIP() << "mounting a small tmpfs needs root";
    if (runCommand("unshare -m true").exitCode != 0) GTEST_SKIP() << "unshare -m is not allowed here (a container without CAP_SYS_ADMIN)";
    const fs::path dir = testScratchDir("safety-tmpfs");
    const fs::path reference = referenceRun(dir);
    uintmax_t bytes = 0;
    for (const auto& e : fs::directory_iterator(reference)) bytes += fs::file_size(e.path());
    // In a private mount namespace: the tmpfs vanishes with it, so nothing is left mounted even
    // if the test dies. Sized at half the run's files (tmpfs counts 4 KiB pages), then grown.
    const fs::path mount = dir / "mnt", kept = dir / "kept";
    fs::create_directories(mount);
    const std::string script = "mount -t tmpfs -o size=" + std::to_string(bytes / 2 / 1024) + "k qsgi-test " + quoted(mount) +
                               " && { " + QSGI_CLI + " " + renderArguments() + " --quiet --out " + quoted(mount / "out") +
                               "; echo \\\"first=\\$?\\\"; mount -o remount,size=64m " + quoted(mount) + " && " + QSGI_CLI + " " +
                               renderArguments() + " --resume --quiet --out " + quoted(mount / "out") +
                               "; echo \\\"resumed=\\$?\\\"; cp -a " + quoted(mount / "out") + " " + quoted(kept) + "; }";
    const CommandResult r = runCommand("unshare -m sh -c \"" + script + "\"");
    ASSERT_NE(r.output.find("first=74"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("No space left on device"), std::string::npos) << r.output;
    ASSERT_NE(r.output.find("resumed=0"), std::string::npos) << r.output;
    expectSameFrameFiles(reference, kept);
    expectConsistent(kept);
}

TEST(OutputSafety, OneRunPerFolderAtATime) {
    const fs::path dir = testScratchDir("safety-lock");
    const fs::path out = dir / "out";
    fs::create_directories(out);
    // Held by another process (this test): the render stops at once, naming the folder and the holder.
    const int fd = ::open((out / ".qsgi-lock").c_str(), O_RDWR | O_CREAT, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    const std::string holder = "pid 4242 on host elsewhere since 2026-01-01T00:00:00Z (qsgi render)\n";
    ASSERT_EQ(::write(fd, holder.data(), holder.size()), ssize_t(holder.size()));
    const CommandResult busy = runQsgi(renderArguments("0:1") + " --out " + quoted(out));
    EXPECT_EQ(busy.exitCode, 75) << busy.output;
    EXPECT_NE(busy.output.find(out.string()), std::string::npos) << busy.output;
    EXPECT_NE(busy.output.find("pid 4242 on host elsewhere"), std::string::npos) << busy.output;
    EXPECT_TRUE(frameFiles(out).empty());
    EXPECT_FALSE(fs::exists(out / "timing.json"));
    // Its holder gone (the kernel drops a dead process's lock; the stale line stays): the next run proceeds.
    ::close(fd);
    const CommandResult after = runQsgi(renderArguments("0:1") + " --quiet --out " + quoted(out));
    EXPECT_EQ(after.exitCode, 0) << after.output;
    EXPECT_EQ(readFileBytes(out / ".qsgi-lock").find("pid 4242"), std::string::npos);

    // A hard link to someone's file planted as the lock file: locked, but never truncated or
    // written (it is that other file too).
    const fs::path linked = dir / "linked", victim = dir / "victim.txt";
    fs::create_directories(linked);
    {
        std::ofstream(victim) << "not a lock file\n";
    }
    fs::create_hard_link(victim, linked / ".qsgi-lock");
    const CommandResult throughLink = runQsgi(renderArguments("0:0") + " --quiet --out " + quoted(linked));
    EXPECT_EQ(throughLink.exitCode, 0) << throughLink.output;
    EXPECT_EQ(readFileBytes(victim), "not a lock file\n");

    // Two renders started together into one folder: one renders, the other (if they overlapped)
    // stops with 75; the folder holds one whole run either way.
    const fs::path together = dir / "together";
    const std::string one = std::string(QSGI_CLI) + " " + renderArguments() + " --quiet --out " + quoted(together);
    const CommandResult both = runCommand("(" + one + "; echo \"a=$?\") & (" + one + "; echo \"b=$?\") & wait");
    const bool aDone = both.output.find("a=0") != std::string::npos, bDone = both.output.find("b=0") != std::string::npos;
    EXPECT_TRUE(aDone || bDone) << both.output;
    EXPECT_TRUE((aDone || both.output.find("a=75") != std::string::npos) && (bDone || both.output.find("b=75") != std::string::npos))
        << both.output;
    const fs::path reference = referenceRun(dir);
    expectSameFrameFiles(reference, together);
    expectConsistent(together);
}

TEST(OutputSafety, AFileSystemThatCannotLockWarnsAndRenders) {
    const fs::path dir = testScratchDir("safety-nolock");
    const CommandResult r = runPreloaded("QSGI_FAIL_FLOCK=1", renderArguments("0:0") + " --out " + quoted(dir / "out"));
    EXPECT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("cannot lock"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("No locks available"), std::string::npos) << r.output;
    expectConsistent(dir / "out");
}

TEST(OutputSafety, NamesAreBytesALatin1SceneAndFolderRenderAndAreRecordedLosslessly) {
    const fs::path dir = testScratchDir("safety-latin1");
    const fs::path cornell = sourceDir() / "data" / "cornell";
    // "cafe\xe9" with é in Latin-1: not UTF-8.
    const std::string latin1 = "caf\xe9";
    const fs::path scenes = dir / latin1;
    fs::create_directories(scenes);
    for (const auto& e : fs::directory_iterator(cornell)) fs::copy_file(e.path(), scenes / e.path().filename());
    fs::rename(scenes / "cornell.gltf", scenes / (latin1 + ".gltf"));
    const fs::path scene = scenes / (latin1 + ".gltf"), out = dir / ("out-" + latin1);
    const std::string arguments = "render " + quoted(scene) + " --animation " + quoted(scenes / "animation.json") +
                                  " --frames 0:1 --photons 20000 --quiet" + kCheapSecondPass + " --out " + quoted(out);
    const CommandResult r = runQsgi(arguments);
    ASSERT_EQ(r.exitCode, 0) << r.output;
    const nlohmann::json log = nlohmann::json::parse(readFileBytes(out / "timing.json"));
    auto hexOf = [](const std::string& bytes) {
        std::string hex;
        for (unsigned char c : bytes) {
            char two[3];
            std::snprintf(two, sizeof two, "%02x", c);
            hex += two;
        }
        return hex;
    };
    EXPECT_EQ(log["scene"]["file"]["hex"], hexOf(scene.string())) << log["scene"];
    EXPECT_NE(log["scene"]["file"]["text"].get<std::string>().find("caf\xef\xbf\xbd.gltf"), std::string::npos);
    EXPECT_EQ(log["inputs"]["options"]["scene"]["hex"], hexOf(scene.string()));
    // The name's bytes are fingerprinted as they are: the same render continues the folder.
    const CommandResult again = runQsgi(arguments + " --resume");
    EXPECT_EQ(again.exitCode, 0) << again.output;
    const CommandResult inspect = runQsgi("inspect --json " + quoted(scene));
    EXPECT_EQ(inspect.exitCode, 0) << inspect.output;
}
