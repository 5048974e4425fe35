// The output folder (--out), opened once. Every file qsgi writes there goes through write():
// created exclusively (O_CREAT|O_EXCL|O_NOFOLLOW) under a temporary name unique to this process,
// relative to the folder's handle, then renamed into place. A symbolic link someone planted at any
// name qsgi uses (a temporary, a frame, timing.json) is replaced, never written through: nothing
// outside the folder is ever opened for writing (docs/design.md §7). Readers see either the old
// file or the complete new one; after write() returns, the file survives a crash under its name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "util/error.h"
#include "util/file_record.h"

namespace qsgi {

// A write whose file is in place under its name, but whose rename may not survive a crash.
class NotDurableError : public EnvironmentError {
public:
    using EnvironmentError::EnvironmentError;
};

class OutputDirectory {
public:
    // Opens `folder`, creating it and its parents when missing. Throws InputError when something
    // other than a folder stands there or it cannot be created for a reason the user controls
    // (permissions, read-only file system), EnvironmentError otherwise.
    explicit OutputDirectory(std::filesystem::path folder);
    ~OutputDirectory();
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;

    const std::filesystem::path& path() const { return path_; }
    int fd() const { return fd_; }  // O_RDONLY|O_DIRECTORY, for *at() calls

    // Writes `bytes` under `name` (no path) atomically and durably; returns what timing.json
    // records of it. Throws EnvironmentError naming the folder, the file and the system's reason
    // (No space left on device…); the temporary is gone either way, and `name` holds what it held
    // before — except for NotDurableError: the file is in place, but the folder could not be
    // synced after the rename.
    FileRecord write(const std::string& name, std::string_view bytes);

    // The same, for a file made in pieces too large to hold at once (asset.usda): `produce` hands
    // each piece to its argument in order. If it throws, nothing is left and `name` keeps what it held.
    using PieceWriter = std::function<void(std::string_view)>;
    FileRecord writeStreamed(const std::string& name, const std::function<void(const PieceWriter&)>& produce);

    // Throws InputError (permissions, read-only) or EnvironmentError unless a file can be
    // created here: found out before the first frame's work, not after it.
    void probeWritable();

    // Unlinks `name` (a link itself, never what it points to); a missing name is fine. Returns
    // whether something was removed; throws EnvironmentError when it cannot be.
    bool remove(const std::string& name);

    // Removes the temporaries killed processes left (write()'s names, and older qsgi's
    // "*.qsgi-tmp.*"). Only while holding the folder's lock: another live run's would go too.
    size_t removeStaleTemporaries();

    // The folder's entries' names, sorted. Throws InputError when it cannot be read.
    std::vector<std::string> names() const;

    // Whether `name` is one of write()'s temporaries (of any process) or an older qsgi's.
    static bool isTemporaryName(const std::string& name);

private:
    // Creates a temporary for `name` exclusively; its name goes to `temporary`. -1 and errno on failure.
    int createTemporary(const std::string& name, std::string& temporary);

    std::filesystem::path path_;
    int fd_ = -1;
    uint64_t temporaries_ = 0;  // made by this object: with the pid, what makes names unique
};

// One file written as OutputDirectory::write does, for tools and tests outside a render.
FileRecord writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace qsgi
