// One output folder holds one run. Before a render writes into a folder, it looks at what the
// folder holds: nothing of qsgi's; frames of this very run (the same fingerprint: a plain render
// recomputes its frame range and keeps the other frames, --resume continues after the complete
// ones); another run's frames (refused, naming each setting that differs with both values, unless
// --overwrite); or frame files that no timing.json describes (refused unless --overwrite).
// `qsgi inspect` reports the same survey without writing anything.
#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "util/error.h"
#include "util/frame_timing.h"

namespace qsgi {

// What a run expects of its folder, as plain values (the pipeline derives them from its settings:
// lib/pipeline/render_job.h's folderExpectations).
struct FolderExpectations {
    // The run's fingerprint (lib/pipeline/run_fingerprint.h): its digest, the parts timing.json
    // records, and what differs between an earlier run's parts and these, one phrase each.
    std::string digest;
    nlohmann::json parts;
    std::function<std::vector<std::string>(const nlohmann::json& there, const nlohmann::json& here)> differences;
    std::vector<std::string> frameExtensions;  // the files every frame has: "ply", and "exr", "png" as the run writes them
    bool resume = false, overwrite = false;
};

struct OutputFolderSurvey {
    enum class Holds {
        Nothing,       // missing, empty, or no frame files and no timing.json
        ThisRun,       // a timing.json with this run's fingerprint
        AnotherRun,    // a timing.json with another fingerprint, or one qsgi cannot read
        UnknownFiles,  // frame files without a timing.json
    };
    std::filesystem::path folder;
    bool exists = false;     // as a folder
    bool notAFolder = false;  // something else stands under the name (a file): refused
    Holds holds = Holds::Nothing;
    // ThisRun: the frames its timing.json lists whose files are all on disk as it records them
    // (verified: regular files, not links, of the recorded size and checksum), in the log's order.
    std::vector<FrameTiming> completeFrames;
    // ThisRun: the frames it lists that fail that check, and why ("frame_0002.ply has 1234 bytes,
    // timing.json says 2468"). A render computes them again or, outside its frames, removes them.
    struct FailedFrame {
        int frame;
        std::string reason;
    };
    std::vector<FailedFrame> failedFrames;
    // AnotherRun: what differs ("photons 20000 there, 1000000 here"), or why the log is unreadable.
    std::vector<std::string> differences;
    // Every frame_NNNN.* file or link in the folder (what --overwrite unlinks, with timing.json).
    std::vector<std::filesystem::path> frameFiles;
    // Entries under a frame file's name that are no file (a folder, a FIFO): refused.
    std::vector<std::filesystem::path> blockingEntries;
};

// The whole-run files, made from every frame after the last (--gltf-out, --usd-out): they go with
// the frames, and a run that computes frames removes them before any frame changes.
inline constexpr const char* kBakedAssetName = "asset.glb";
inline constexpr const char* kUsdAssetName = "asset.usda";
inline constexpr const char* kWholeRunFileNames[] = {kBakedAssetName, kUsdAssetName};

// "frame_0012.ply" and the like.
std::string frameFileName(int frame, const char* extension);
// "frame_0012.ply", "frame_12345.exr": a frame file's name as frameFileName writes it, with one
// of the extensions qsgi writes (ply, exr, png, glb); not a temporary, not "frame_0003.png.bak".
bool isFrameFileName(const std::string& name);

// Why `frame`'s files in the folder open as `folderFd` are not as `record` lists them (every file
// of `extensions` listed; every listed file verified by fileMismatch), or nullopt when they are.
// A file that cannot be read throws EnvironmentError naming it (fileMismatch): it proves nothing.
std::optional<std::string> frameFilesProblem(int folderFd, const FrameTiming& record, const std::vector<std::string>& extensions,
                                             const std::string& folderName);

// The names of a frame's files, whichever the settings write: what a failed frame's removal unlinks.
std::vector<std::string> frameFileNames(int frame);

// Reads the folder; writes nothing. With `verify`, every frame file of this run's is read whole
// to verify it; without, the frames the log lists count as complete (for a refusal's first look).
OutputFolderSurvey surveyOutputFolder(const std::filesystem::path& folder, const FolderExpectations& expected,
                                      bool verify = true);

// The first frame of first..last that the survey's complete frames of this run do not hold
// (last + 1 when they hold them all): where --resume starts.
int firstIncompleteFrame(const OutputFolderSurvey& survey, int first, int last);

// Why a run expecting this (--resume, --overwrite) may not write into the surveyed folder: one
// message naming the folder and each differing setting, or nullopt when it may.
std::optional<InputError> outputFolderRefusal(const OutputFolderSurvey& survey, const FolderExpectations& expected);

// For --overwrite: unlinks the earlier run's frame files and its timing.json, nothing else (never
// recursively: not chunks/, not slurm/, not another file of the user's). Returns how many.
size_t removeEarlierRun(const OutputFolderSurvey& survey);

}  // namespace qsgi
