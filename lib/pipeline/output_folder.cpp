#include "pipeline/output_folder.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <set>

#include "output/timing_log.h"

namespace qsgi {

namespace fs = std::filesystem;

std::string frameFileName(int frame, const char* extension) {
    char name[64];
    std::snprintf(name, sizeof name, "frame_%04d.%s", frame, extension);
    return name;
}

bool isFrameFileName(const std::string& name) {
    constexpr size_t kPrefix = 6;  // "frame_"
    if (name.rfind("frame_", 0) != 0) return false;
    size_t digits = 0;
    while (kPrefix + digits < name.size() && std::isdigit(static_cast<unsigned char>(name[kPrefix + digits]))) ++digits;
    return digits >= 4 && kPrefix + digits + 1 < name.size() && name[kPrefix + digits] == '.' &&
           name.find(".qsgi-") == std::string::npos;
}

bool frameFilesComplete(const fs::path& folder, int frame, const RenderSettings& s) {
    std::error_code missing;
    return fs::exists(folder / frameFileName(frame, "ply"), missing) &&
           (!s.writeExr || fs::exists(folder / frameFileName(frame, "exr"), missing)) &&
           (!s.writePng || fs::exists(folder / frameFileName(frame, "png"), missing)) &&
           (!s.writeGltf || fs::exists(folder / frameFileName(frame, "glb"), missing));
}

OutputFolderSurvey surveyOutputFolder(const fs::path& folder, const RunFingerprint& fingerprint,
                                      const RenderSettings& settings) {
    OutputFolderSurvey survey;
    survey.folder = folder;
    std::error_code ec;
    survey.exists = fs::is_directory(folder, ec);
    survey.notAFolder = !survey.exists && fs::exists(folder, ec);
    if (!survey.exists) return survey;
    try {
        for (const auto& entry : fs::directory_iterator(folder))
            if (isFrameFileName(entry.path().filename().string())) survey.frameFiles.push_back(entry.path());
    } catch (const fs::filesystem_error& e) {
        throw InputError(folder.string(), "--out", std::string("cannot read the output folder: ") + e.code().message());
    }
    std::sort(survey.frameFiles.begin(), survey.frameFiles.end());

    const fs::path logPath = folder / "timing.json";
    if (!fs::exists(logPath, ec)) {
        survey.holds = survey.frameFiles.empty() ? OutputFolderSurvey::Holds::Nothing : OutputFolderSurvey::Holds::UnknownFiles;
        return survey;
    }
    EarlierRun earlier;
    try {
        earlier = readTimingLog(logPath);
    } catch (const InputError& e) {
        survey.holds = OutputFolderSurvey::Holds::AnotherRun;
        survey.differences.push_back("its timing.json cannot be read, so nothing says which run it holds: " + e.problem());
        return survey;
    }
    if (earlier.inputsFingerprint != fingerprint.digest) {
        survey.holds = OutputFolderSurvey::Holds::AnotherRun;
        survey.differences = fingerprintDifferences(earlier.inputs, fingerprint.parts);
        // The digest also covers what the parts cannot show one by one.
        if (survey.differences.empty()) survey.differences.push_back("the inputs' fingerprints differ");
        return survey;
    }
    survey.holds = OutputFolderSurvey::Holds::ThisRun;
    for (const FrameTiming& f : earlier.frames)
        if (frameFilesComplete(folder, f.frame, settings)) survey.completeFrames.push_back(f);
    return survey;
}

int firstIncompleteFrame(const OutputFolderSurvey& survey, int first, int last) {
    std::set<int> complete;
    for (const FrameTiming& f : survey.completeFrames) complete.insert(f.frame);
    int next = first;
    while (next <= last && complete.count(next)) ++next;
    return next;
}

std::optional<InputError> outputFolderRefusal(const OutputFolderSurvey& survey, const RenderSettings& settings) {
    using Holds = OutputFolderSurvey::Holds;
    const std::string place = settings.resume ? "--resume" : "--out";
    if (survey.notAFolder) return InputError(survey.folder.string(), "--out", "is not a folder");
    if (settings.overwrite || survey.holds == Holds::Nothing || survey.holds == Holds::ThisRun) return std::nullopt;
    if (survey.holds == Holds::UnknownFiles)
        return InputError(survey.folder.string(), place,
                          "holds frame files but no timing.json, so nothing says how they were made; render into an "
                          "empty folder, or add --overwrite to replace them");
    std::string what;
    for (const std::string& d : survey.differences) what += (what.empty() ? "" : "; ") + d;
    return InputError(survey.folder.string(), place,
                      "holds a render from other inputs or settings (" + what + "), so " +
                          (settings.resume ? "--resume" : "rendering into it") +
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
