// One output folder holds one run (issue 31): a render into a folder of the same run proceeds and
// its timing.json then lists every frame the folder holds; a folder of another run is refused,
// naming each setting that differs with both values (with or without --resume), and is left as
// it was; --overwrite unlinks exactly the earlier run's frame files and timing.json, nothing else.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "output/folder_survey.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace {

std::string cornellRender(const std::string& frames, const std::string& options, bool quiet = true) {
    const fs::path cornell = sourceDir() / "data" / "cornell";
    return "render " + (cornell / "cornell.gltf").string() + " --animation " + (cornell / "animation.json").string() +
           " --frames " + frames + " --width 20 --height 15 " + (quiet ? "--quiet " : "") + options + kCheapSecondPass;
}

std::set<std::string> namesIn(const fs::path& dir) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
    return names;
}

// Every file's bytes, by name (folders by name only).
std::map<std::string, std::string> contents(const fs::path& dir) {
    std::map<std::string, std::string> bytes;
    for (const auto& e : fs::directory_iterator(dir))
        bytes[e.path().filename().string()] = fs::is_directory(e.path()) ? "<folder>" : readFileBytes(e.path());
    return bytes;
}

}  // namespace

TEST(OutputFolder, FrameFileNamesAreRecognisedExactly) {
    for (const char* name : {"frame_0000.ply", "frame_0012.exr", "frame_12345.png", "frame_9999.glb"})
        EXPECT_TRUE(qsgi::isFrameFileName(name)) << name;
    for (const char* name : {"frame_000.ply", "frame_0001", "frame_0001.", "frames_0001.ply", "frame_00a1.ply", "timing.json",
                             "my_frame_0001.ply", "frame_.ply", "frame_0001.qsgi-tmp.ply", "frame_0001.ply.qsgi-merge-tmp",
                             "frame_0001.x", "frame_0003.png.bak", "frame_0003.ply~", "frame_0003.PLY"})
        EXPECT_FALSE(qsgi::isFrameFileName(name)) << name;
    EXPECT_EQ(qsgi::frameFileName(7, "ply"), "frame_0007.ply");
    EXPECT_TRUE(qsgi::isFrameFileName(qsgi::frameFileName(123456, "exr")));
}

// Re-running a render (scripts/run.sh twice, a shorter range after a longer one) is the same run:
// it proceeds, writes the same bytes, and the log lists every frame on disk.
TEST(OutputFolder, ARenderIntoItsOwnRunsFolderProceedsAndTheLogListsEveryFrame) {
    const fs::path out = fs::path(testScratchDir("folder-same")) / "out";
    const std::string options = "--photons 20000 --no-exr --out " + out.string();
    ASSERT_EQ(runQsgi(cornellRender("0:4", options)).exitCode, 0);
    const std::string frame1 = readFileBytes(out / "frame_0001.ply");
    const CommandResult again = runQsgi(cornellRender("0:1", options));
    ASSERT_EQ(again.exitCode, 0) << again.output;
    EXPECT_EQ(readFileBytes(out / "frame_0001.ply"), frame1);
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0, 1, 2, 3, 4}));
    // The summary says what else the folder holds; another thread count is the same run.
    const CommandResult told = runQsgi(cornellRender("1:2", options + " --threads 1", false));
    ASSERT_EQ(told.exitCode, 0) << told.output;
    EXPECT_NE(told.output.find("wrote 2 frames"), std::string::npos) << told.output;
    EXPECT_NE(told.output.find("also holds 3 earlier frames of the same run"), std::string::npos) << told.output;
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(OutputFolder, AnotherRunsFolderIsRefusedNamingEachDifferenceAndOverwriteLeavesExactlyOneRun) {
    const fs::path dir = testScratchDir("folder-other");
    const fs::path out = dir / "out";
    ASSERT_EQ(runQsgi(cornellRender("0:3", "--photons 20000 --no-exr --out " + out.string())).exitCode, 0);
    // Things of the user's (and of a split run's) beside the frames: never touched.
    fs::create_directories(out / "chunks" / "c0");
    std::ofstream(out / "chunks" / "c0" / "frame_0000.ply") << "a chunk's frame";
    std::ofstream(out / "notes.txt") << "mine";
    const auto before = contents(out);

    const std::string other = "--photons 30000 --estimator detp --no-exr --out " + out.string();
    for (const char* mode : {"", " --resume"}) {
        SCOPED_TRACE(mode);
        const CommandResult r = runQsgi(cornellRender("0:1", other + mode));
        EXPECT_EQ(r.exitCode, 2) << r.output;
        EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
        for (const std::string& words : {std::string("photons 20000 there, 30000 here"),
                                         std::string("estimator impact-count there, detp here"), std::string("--overwrite"),
                                         out.string()})
            EXPECT_NE(r.output.find(words), std::string::npos) << "should say '" << words << "': " << r.output;
        EXPECT_NE(r.output.find(*mode ? "--resume" : "--out"), std::string::npos) << r.output;
        EXPECT_EQ(contents(out), before) << "a refused render must leave the folder as it was";
    }

    const CommandResult replaced = runQsgi(cornellRender("0:1", other + " --overwrite"));
    ASSERT_EQ(replaced.exitCode, 0) << replaced.output;
    // Theirs, the new run's, and the folder's lock (which stays, naming its last holder).
    EXPECT_EQ(namesIn(out), (std::set<std::string>{"chunks", "notes.txt", "frame_0000.ply", "frame_0001.ply", "timing.json",
                                                   ".qsgi-lock"}));
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0, 1}));
    EXPECT_EQ(readFileBytes(out / "notes.txt"), "mine");
    EXPECT_EQ(readFileBytes(out / "chunks" / "c0" / "frame_0000.ply"), "a chunk's frame");
    EXPECT_EQ(nlohmann::json::parse(readFileBytes(out / "timing.json"))["config"]["estimator"], "detp");
    // The folder now holds the new run alone: it is that run's to continue.
    const CommandResult resumed = runQsgi(cornellRender("0:2", other + " --resume"));
    EXPECT_EQ(resumed.exitCode, 0) << resumed.output;
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0, 1, 2}));
}

TEST(OutputFolder, FrameFilesWithoutALogAreRefusedUnlessOverwritten) {
    const fs::path out = fs::path(testScratchDir("folder-orphans")) / "out";
    fs::create_directories(out);
    std::ofstream(out / "frame_0000.ply") << "not ours";
    const std::string options = "--photons 20000 --no-exr --out " + out.string();
    const CommandResult refused = runQsgi(cornellRender("0:0", options));
    EXPECT_EQ(refused.exitCode, 2) << refused.output;
    EXPECT_NE(refused.output.find("no timing.json"), std::string::npos) << refused.output;
    EXPECT_EQ(readFileBytes(out / "frame_0000.ply"), "not ours");
    ASSERT_EQ(runQsgi(cornellRender("0:0", options + " --overwrite")).exitCode, 0);
    EXPECT_NE(readFileBytes(out / "frame_0000.ply"), "not ours");
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0}));
}

// What cannot hold a run is refused before anything is written: a file standing where the folder
// should be, a timing.json that cannot be read (nothing says which run it holds); --overwrite
// replaces the latter and says so, also together with --resume.
TEST(OutputFolder, AFileOrAnUnreadableLogIsRefusedAndOverwriteSaysWhatItUnlinked) {
    const fs::path dir = testScratchDir("folder-odd");
    const fs::path file = dir / "a-file";
    std::ofstream(file) << "mine";
    const CommandResult onFile = runQsgi(cornellRender("0:0", "--photons 2000 --no-exr --out " + file.string()));
    EXPECT_EQ(onFile.exitCode, 2) << onFile.output;
    EXPECT_NE(onFile.output.find("is not a folder"), std::string::npos) << onFile.output;
    EXPECT_EQ(readFileBytes(file), "mine");

    const fs::path out = dir / "out";
    fs::create_directories(out);
    std::ofstream(out / "timing.json") << "{ not json";
    std::ofstream(out / "frame_0000.ply") << "?";
    const auto before = contents(out);
    const std::string options = "--photons 2000 --no-exr --out " + out.string();
    const CommandResult refused = runQsgi(cornellRender("0:0", options));
    EXPECT_EQ(refused.exitCode, 2) << refused.output;
    EXPECT_NE(refused.output.find("timing.json cannot be read"), std::string::npos) << refused.output;
    EXPECT_EQ(contents(out), before);
    const CommandResult replaced = runQsgi(cornellRender("0:0", options + " --resume --overwrite", false));
    ASSERT_EQ(replaced.exitCode, 0) << replaced.output;
    EXPECT_NE(replaced.output.find("--overwrite: unlinked 2 files of another run"), std::string::npos) << replaced.output;
    EXPECT_EQ(loggedFrames(out), (std::vector<int>{0}));
}
