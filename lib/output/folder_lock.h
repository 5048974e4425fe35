// One run per output folder at a time. The lock is flock(2) on the folder's .qsgi-lock file,
// taken before anything else touches the folder (before stale temporaries are cleaned: they
// could be a live run's), held for the whole run and released by the kernel when the process
// ends however it ends, so a killed run (a requeued Slurm task) never blocks the next one. The
// file stays, holding the last holder's line ("pid 1234 on host node07 since …"). The Slurm merge
// (scripts/qsgibatch/output_folder.py) takes the same lock the same way.
#pragma once

#include <string>

#include "output/output_directory.h"

namespace qsgi {

class FolderLock {
public:
    static constexpr const char* kFileName = ".qsgi-lock";

    // Takes the lock of `folder` and writes "pid P on host H since T (what)" in it. Throws
    // FolderBusyError naming the folder and the holder when another process holds it, InputError
    // when something not qsgi's stands at the name. Where the file system cannot lock (some NFS
    // or Lustre mounts), the run goes on unguarded: held() is false and unguardedReason() says why.
    FolderLock(const OutputDirectory& folder, const std::string& what);
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

    bool held() const { return held_; }
    const std::string& unguardedReason() const { return unguardedReason_; }

private:
    int fd_ = -1;
    bool held_ = false;
    std::string unguardedReason_;
};

}  // namespace qsgi
