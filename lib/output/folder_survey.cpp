#include "output/folder_survey.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <set>

#include "output/file_checksum.h"
#include "output/timing_log.h"

namespace qsgi {

namespace fs = std::filesystem;

std::string frameFileName(int frame, const char* extension) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%04d.%s", frame, extension);
    return name;
}

bool isFrameFileName(const std::string& name) {
    for (const char* wholeRun : kWholeRunFileNames)
        if (name == wholeRun) return true;  // made from the frames: goes with them
    constexpr size_t kPrefix = 6;  // "frame_"
    if (name.rfind("frame_", 0) != 0) return false;
    size_t digits = 0;
    while (kPrefix + digits < name.size() && std::isdigit(static_cast<unsigned char>(name[kPrefix + digits]))) ++digits;
    if (digits < 4 || kPrefix + digits >= name.size() || name[kPrefix + digits] != '.') return false;
    // Only the kinds qsgi writes: a user's frame_0003.png.bak or frame_0003.txt is not ours to unlink.
    const std::string extension = name.substr(kPrefix + digits + 1);
    return extension == "ply" || extension == "exr" || extension == "png" || extension == "glb";
}

std::vector<std::string> frameFileNames(int frame) {
    return {frameFileName(frame, "ply"), frameFileName(frame, "exr"), frameFileName(frame, "png"), frameFileName(frame, "glb")};
}

std::optional<std::string> frameFilesProblem(int folderFd, const FrameTiming& record, const std::vector<std::string>& extensions,
                                             const std::string& folderName) {
    if (record.files.empty()) return std::string("timing.json (an older qsgi's) records no checksums to verify its files by");
    std::vector<std::string> wanted;
    for (const std::string& extension : extensions) wanted.push_back(frameFileName(record.frame, extension.c_str()));
    // Exactly the names qsgi gives this frame's files: a hand-edited name ("../x") reads nothing
    // outside the folder.
    const std::vector<std::string> names = frameFileNames(record.frame);
    for (const FileRecord& file : record.files)
        if (std::find(names.begin(), names.end(), file.name) == names.end())
            return "timing.json lists '" + file.name + "', not a file of this frame";
    for (const std::string& name : wanted) {
        const bool listed = std::any_of(record.files.begin(), record.files.end(), [&](const FileRecord& f) { return f.name == name; });
        if (!listed) return name + " is not among the files timing.json lists for it";
    }
    for (const FileRecord& file : record.files)
        if (const std::optional<std::string> mismatch = fileMismatch(folderFd, file, folderName)) return file.name + " " + *mismatch;
    return std::nullopt;
}

OutputFolderSurvey surveyOutputFolder(const fs::path& folder, const FolderExpectations& expected, bool verify) {
    OutputFolderSurvey survey;
    survey.folder = folder;
    std::error_code ec;
    survey.exists = fs::is_directory(folder, ec);
    survey.notAFolder = !survey.exists && fs::exists(folder, ec);
    if (!survey.exists) return survey;
    try {
        for (const auto& entry : fs::directory_iterator(folder)) {
            if (!isFrameFileName(entry.path().filename().string())) continue;
            const fs::file_status status = entry.symlink_status();
            if (!fs::is_regular_file(status) && !fs::is_symlink(status)) survey.blockingEntries.push_back(entry.path());
            else survey.frameFiles.push_back(entry.path());
        }
    } catch (const fs::filesystem_error& e) {
        throw InputError(folder.string(), "--out", std::string("cannot read the output folder: ") + e.code().message());
    }
    std::sort(survey.frameFiles.begin(), survey.frameFiles.end());
    std::sort(survey.blockingEntries.begin(), survey.blockingEntries.end());

    const fs::path logPath = folder / "timing.json";
    const fs::file_status logStatus = fs::symlink_status(logPath, ec);
    if (!fs::exists(logStatus)) {
        survey.holds = survey.frameFiles.empty() ? OutputFolderSurvey::Holds::Nothing : OutputFolderSurvey::Holds::UnknownFiles;
        return survey;
    }
    EarlierRun earlier;
    if (!fs::is_regular_file(logStatus)) {
        survey.holds = OutputFolderSurvey::Holds::AnotherRun;
        survey.differences.push_back(std::string("its timing.json is ") +
                                     (fs::is_symlink(logStatus) ? "a symbolic link" : "not a regular file") + ", not a log qsgi wrote");
        return survey;
    }
    try {
        earlier = readTimingLog(logPath);
    } catch (const InputError& e) {
        survey.holds = OutputFolderSurvey::Holds::AnotherRun;
        survey.differences.push_back("its timing.json cannot be read, so nothing says which run it holds: " + e.problem());
        return survey;
    }
    if (earlier.inputsFingerprint != expected.digest) {
        survey.holds = OutputFolderSurvey::Holds::AnotherRun;
        if (expected.differences) survey.differences = expected.differences(earlier.inputs, expected.parts);
        // The digest also covers what the parts cannot show one by one.
        if (survey.differences.empty()) survey.differences.push_back("the inputs' fingerprints differ");
        return survey;
    }
    survey.holds = OutputFolderSurvey::Holds::ThisRun;
    const int folderFd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (folderFd < 0)
        throw InputError(folder.string(), "--out", std::string("cannot read the output folder: ") + std::strerror(errno));
    try {
        for (const FrameTiming& f : earlier.frames) {
            const std::optional<std::string> problem = verify ? frameFilesProblem(folderFd, f, expected.frameExtensions, folder.string()) : std::nullopt;
            if (problem) survey.failedFrames.push_back({f.frame, *problem});
            else survey.completeFrames.push_back(f);
        }
    } catch (...) {
        ::close(folderFd);
        throw;
    }
    ::close(folderFd);
    return survey;
}

int firstIncompleteFrame(const OutputFolderSurvey& survey, int first, int last) {
    std::set<int> complete;
    for (const FrameTiming& f : survey.completeFrames) complete.insert(f.frame);
    int next = first;
    while (next <= last && complete.count(next)) ++next;
    return next;
}

std::optional<InputError> outputFolderRefusal(const OutputFolderSurvey& survey, const FolderExpectations& expected) {
    using Holds = OutputFolderSurvey::Holds;
    const std::string place = expected.resume ? "--resume" : "--out";
    if (survey.notAFolder) return InputError(survey.folder.string(), "--out", "is not a folder");
    // Not even --overwrite unlinks what is not a file: refused before any work, not at its write.
    if (!survey.blockingEntries.empty())
        return InputError(survey.blockingEntries.front().string(), place,
                          "is a folder (or other non-file) where qsgi writes a frame file; move it away");
    if (expected.overwrite || survey.holds == Holds::Nothing || survey.holds == Holds::ThisRun) return std::nullopt;
    if (survey.holds == Holds::UnknownFiles)
        return InputError(survey.folder.string(), place,
                          "holds frame files but no timing.json, so nothing says how they were made; render into an "
                          "empty folder, or add --overwrite to replace them");
    std::string what;
    for (const std::string& d : survey.differences) what += (what.empty() ? "" : "; ") + d;
    return InputError(survey.folder.string(), place,
                      "holds a render from other inputs or settings (" + what + "), so " +
                          (expected.resume ? "--resume" : "rendering into it") +
                          " would mix two runs; use the same settings, render into another folder, or add --overwrite "
                          "to replace its frames and timing.json");
}

size_t removeEarlierRun(const OutputFolderSurvey& survey) {
    std::error_code ec;
    size_t removed = 0;
    for (const fs::path& file : survey.frameFiles) {
        // A folder named like a frame file is not a frame file: left alone.
        if (fs::is_directory(fs::symlink_status(file, ec))) continue;
        if (!fs::remove(file, ec) && ec)
            throw InputError(file.string(), "--overwrite", "cannot remove the earlier run's file: " + ec.message());
        ++removed;
    }
    const fs::path log = survey.folder / "timing.json";
    if (fs::exists(fs::symlink_status(log, ec))) {
        if (!fs::remove(log, ec) && ec)
            throw InputError(log.string(), "--overwrite", "cannot remove the earlier run's timing.json: " + ec.message());
        ++removed;
    }
    return removed;
}

}  // namespace qsgi
