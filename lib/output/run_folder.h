// One run's output folder (docs/design.md §7): the one owner of the folder's protocol. Opening it
// surveys the folder twice — first touching nothing, so that a refused render leaves the folder as
// it was; then under the folder's lock, which decides — refuses another run's frames unless
// --overwrite replaces them, and finds where --resume starts. Then the log is started (earlier
// frames kept, damaged ones forgotten before their files go), each frame is committed as one
// transaction (every file, then the log listing them; a failure leaves the frames the log lists
// whole), and the whole-run files (asset.glb, asset.usda) go through the same door.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "output/folder_lock.h"
#include "output/folder_survey.h"
#include "output/frame_sink.h"
#include "output/output_directory.h"
#include "output/timing_log.h"

namespace qsgi {

class RunFolder {
public:
    using Warn = std::function<void(const std::string&)>;

    // Throws InputError when the folder refuses the run (a file at its name, another run's frames
    // without --overwrite, frame files no log describes), FolderBusyError when another run holds
    // it, InputError or EnvironmentError when it cannot be written. `holder` names the run in the
    // lock file ("qsgi render").
    RunFolder(const std::filesystem::path& folder, FolderExpectations expected, const std::string& holder, const Warn& warn);
    RunFolder(const RunFolder&) = delete;
    RunFolder& operator=(const RunFolder&) = delete;

    OutputDirectory& directory() { return out_; }
    // Files of another run that --overwrite unlinked (frame files and timing.json).
    int filesReplaced() const { return filesReplaced_; }
    // Where the run starts: with --resume, the first frame of first..last the folder does not hold
    // whole (last + 1 when it holds them all); otherwise first.
    int startFrame(int first, int last) const;

    // What starting the log found of the earlier frames.
    struct Started {
        int framesOutside = 0;  // complete frames of this run outside start..last, kept in the log
        int framesRemoved = 0;  // frames outside start..last whose files failed verification: unlinked
    };
    // Starts the log of a run computing frames start..last (none when start > last): `header` with
    // the folder's complete frames. Written now when frames will be computed or some failed
    // verification (a resumed run computing nothing leaves the log as it is: the Slurm merge's
    // has keys of its own), so that the folder records the run's fingerprint from the start and
    // forgets damaged frames before their files are unlinked. The whole-run files
    // (kWholeRunFileNames) go before any frame changes: made from earlier frames, they would no
    // longer be the folder's.
    Started startLog(TimingLog header, int start, int last);
    TimingLog& log() { return log_; }

    // Writes the frame's files, then the log listing them with `timing`, whose writeSeconds (the
    // encoding's, if the caller timed it) gains the writing's. On a failure (a full
    // disk) the files already placed go unless the log already listed the frame (then each name
    // holds the earlier bytes or the same new ones), and EnvironmentError says what the log lists
    // and where --resume continues.
    void commitFrame(int frame, const std::vector<EncodedFile>& files, FrameTiming timing);

private:
    std::filesystem::path path_;
    FolderExpectations expected_;
    Warn warn_;
    OutputDirectory out_;
    std::optional<FolderLock> lock_;
    OutputFolderSurvey survey_;
    int filesReplaced_ = 0;
    TimingLog log_;
};

}  // namespace qsgi
