#include "output/run_folder.h"

#include <algorithm>

#include "util/stopwatch.h"

namespace qsgi {

namespace {
OutputFolderSurvey surveyedOrRefused(const std::filesystem::path& folder, const FolderExpectations& expected, bool verify) {
    OutputFolderSurvey survey = surveyOutputFolder(folder, expected, verify);
    if (const std::optional<InputError> refusal = outputFolderRefusal(survey, expected)) throw *refusal;
    return survey;
}

// One folder, one run: frames of this run are kept (and with --resume not computed again), another
// run's are refused unless --overwrite replaces them. Judged first without touching anything (the
// folder is not even created), so that a refused render leaves the folder exactly as it was.
const std::filesystem::path& notRefusedAtFirstSight(const std::filesystem::path& folder, const FolderExpectations& expected) {
    surveyedOrRefused(folder, expected, false);
    return folder;
}
}  // namespace

RunFolder::RunFolder(const std::filesystem::path& folder, FolderExpectations expected, const std::string& holder, const Warn& warn)
    : path_(folder),
      expected_(std::move(expected)),
      warn_(warn),
      out_(notRefusedAtFirstSight(folder, expected_)) {
    // Then again under the folder's lock, which decides.
    lock_.emplace(out_, holder);
    if (!lock_->held()) warn_(lock_->unguardedReason());
    survey_ = surveyedOrRefused(folder, expected_, true);
    // Find out now, not after the first frame's work, whether files can be written here.
    out_.probeWritable();
    // Another live run's temporaries would go too: only under the lock.
    if (lock_->held()) out_.removeStaleTemporaries();
    if (survey_.holds != OutputFolderSurvey::Holds::ThisRun && survey_.holds != OutputFolderSurvey::Holds::Nothing)
        filesReplaced_ = int(removeEarlierRun(survey_));
}

int RunFolder::startFrame(int first, int last) const {
    return expected_.resume ? firstIncompleteFrame(survey_, first, last) : first;
}

RunFolder::Started RunFolder::startLog(TimingLog header, int start, int last) {
    log_ = std::move(header);
    const std::vector<FrameTiming> earlierFrames =
        survey_.holds == OutputFolderSurvey::Holds::ThisRun ? survey_.completeFrames : std::vector<FrameTiming>{};
    Started started;
    for (const FrameTiming& f : earlierFrames)
        if (f.frame < start || f.frame > last) log_.frames.push_back(f);
    started.framesOutside = int(log_.frames.size());
    // The earlier frames this run computes again stay listed until each is rewritten (with the
    // same bytes): a run stopped or failing before it reaches them leaves them whole and listed.
    for (const FrameTiming& f : earlierFrames)
        if (f.frame >= start && f.frame <= last) log_.frames.push_back(f);
    // Those failed frames this run holds are computed again; the others it says how to render again.
    if (start <= last || !survey_.failedFrames.empty()) out_.write("timing.json", log_.text());
    for (const OutputFolderSurvey::FailedFrame& failed : survey_.failedFrames) {
        for (const std::string& name : frameFileNames(failed.frame)) out_.remove(name);
        const bool recomputed = failed.frame >= start && failed.frame <= last;
        if (!recomputed || expected_.resume)
            warn_("frame " + std::to_string(failed.frame) + " in " + path_.string() + " is not as timing.json records it (" +
                  failed.reason + "): " +
                  (recomputed ? "computing it again"
                              : "outside --frames, so its files are removed; render it again with --frames " +
                                    std::to_string(failed.frame) + ":" + std::to_string(failed.frame) + " --resume"));
        if (!recomputed) ++started.framesRemoved;
    }
    if (start <= last)
        for (const char* name : kWholeRunFileNames) out_.remove(name);
    return started;
}

void RunFolder::commitFrame(int frame, const std::vector<EncodedFile>& files, FrameTiming timing) {
    Stopwatch clock;
    const double encodeSeconds = timing.writeSeconds;
    const auto listed = std::find_if(log_.frames.begin(), log_.frames.end(), [&](const FrameTiming& f) { return f.frame == frame; });
    const bool listedBefore = listed != log_.frames.end();
    const std::vector<FrameTiming> logBefore = listedBefore ? std::vector<FrameTiming>{} : log_.frames;
    std::string writing;
    try {
        for (const EncodedFile& file : files) {
            writing = frameFileName(frame, file.extension.c_str());
            timing.files.push_back(out_.write(writing, file.bytes));
        }
        timing.writeSeconds = encodeSeconds + clock.seconds();
        if (listedBefore) *listed = timing;
        else log_.frames.push_back(timing);
        writing = "timing.json";
        // Rewritten after every frame, so it always describes the frames on disk (docs/design.md §7).
        out_.write("timing.json", log_.text());
    } catch (const EnvironmentError& e) {
        std::string problem = "writing frame " + std::to_string(frame) + " failed: " + e.problem() + ". ";
        const bool logPlaced = writing == "timing.json" && dynamic_cast<const NotDurableError*>(&e) != nullptr;
        if (listedBefore || logPlaced) {
            // Listed, and whole: each of its names holds the earlier bytes or the same new ones.
            problem += "Its files are whole and listed; ";
        } else {
            // A frame the log on disk does not list: whatever of it was placed goes.
            log_.frames = logBefore;
            std::string failures;
            for (const std::string& name : frameFileNames(frame)) {
                try {
                    out_.remove(name);
                } catch (const EnvironmentError& removal) {
                    failures += (failures.empty() ? "" : "; ") + removal.problem();
                }
            }
            problem += failures.empty() ? "Its files were removed; " : "Removing its files failed too (" + failures + "); ";
        }
        const size_t listedFrames = log_.frames.size();
        problem += "timing.json lists the " + std::to_string(listedFrames) + (listedFrames == 1 ? " frame" : " frames") +
                   " whole on disk; once the cause is fixed, add --resume to continue from frame " + std::to_string(frame);
        throw EnvironmentError(path_.string(), problem);
    }
}

}  // namespace qsgi
