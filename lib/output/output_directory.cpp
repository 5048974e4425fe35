#include "output/output_directory.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "output/file_checksum.h"
#include "util/error.h"

namespace qsgi {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTemporaryPrefix = ".qsgi-tmp.";
constexpr const char* kOldTemporaryMarker = ".qsgi-tmp";  // frame_0001.qsgi-tmp.ply, before issue 32

// Failures of a folder the user chose that another choice fixes (permissions, a read-only file
// system, a file where a folder should be): bad input, exit 2, found before any work. Once the
// folder has been probed, any failure is the machine's (exit 74).
bool isFolderChoiceError(int error) {
    return error == EACCES || error == EPERM || error == EROFS || error == ENOTDIR || error == ENAMETOOLONG ||
           error == ELOOP || error == EEXIST;
}

[[noreturn]] void failChoosing(const fs::path& folder, const std::string& what, int error) {
    if (isFolderChoiceError(error)) throw InputError(folder.string(), "--out", what + ": " + std::strerror(error));
    throw EnvironmentError(folder.string(), what + ": " + std::strerror(error));
}

[[noreturn]] void fail(const fs::path& folder, const std::string& what, int error) {
    throw EnvironmentError(folder.string(), what + ": " + std::strerror(error));
}

// Writes all of `bytes`, retrying short writes and interrupted calls; returns 0 or the errno.
int writeAll(int fd, std::string_view bytes) {
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) return errno;
        if (n == 0) return EIO;
        done += size_t(n);
    }
    return 0;
}

}  // namespace

OutputDirectory::OutputDirectory(fs::path folder) : path_(std::move(folder)) {
    if (path_.empty()) path_ = ".";
    std::error_code ec;
    const fs::file_status status = fs::status(path_, ec);
    if (fs::exists(status) && !fs::is_directory(status)) throw InputError(path_.string(), "--out", "is not a folder");
    if (!fs::exists(status)) {
        fs::create_directories(path_, ec);
        if (ec) failChoosing(path_, "cannot create the output folder", ec.value());
    }
    fd_ = ::open(path_.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0) failChoosing(path_, "cannot open the output folder", errno);
}

OutputDirectory::~OutputDirectory() {
    if (fd_ >= 0) ::close(fd_);
}

bool OutputDirectory::isTemporaryName(const std::string& name) {
    // Older qsgi's: frame_0001.qsgi-tmp.ply, timing.qsgi-tmp.json, and its write probe; nothing
    // else of the user's that happens to hold the marker.
    const bool old = (name.rfind("frame_", 0) == 0 || name.rfind("timing.", 0) == 0) &&
                     name.find(std::string(kOldTemporaryMarker) + ".") != std::string::npos;
    return name.rfind(kTemporaryPrefix, 0) == 0 || old || name == ".qsgi-write-test";
}

int OutputDirectory::createTemporary(const std::string& name, std::string& temporary) {
    // A name no other process makes (the pid) and this one has not made yet (the count); an
    // entry already standing there (planted, or a dead process's with a reused pid) is skipped,
    // never opened.
    for (int attempt = 0;; ++attempt) {
        temporary = kTemporaryPrefix + std::to_string(::getpid()) + "." + std::to_string(temporaries_++) + "." + name;
        const int fd = ::openat(fd_, temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
        if (fd >= 0 || errno != EEXIST || attempt > 1000) return fd;
    }
}

FileRecord OutputDirectory::write(const std::string& name, std::string_view bytes) {
    return writeStreamed(name, [&](const PieceWriter& put) { put(bytes); });
}

FileRecord OutputDirectory::writeStreamed(const std::string& name, const std::function<void(const PieceWriter&)>& produce) {
    std::string temporary;
    const int fd = createTemporary(name, temporary);
    if (fd < 0) fail(path_, "cannot create a file to write " + name, errno);
    int error = 0;
    uint64_t size = 0;
    Xxh3Stream checksum;
    try {
        produce([&](std::string_view piece) {
            if (error) return;  // reported once produce is done
            error = writeAll(fd, piece);
            size += piece.size();
            checksum.update(piece);
        });
    } catch (...) {
        ::close(fd);
        ::unlinkat(fd_, temporary.c_str(), 0);
        throw;
    }
    if (!error && ::fsync(fd) != 0) error = errno;
    if (::close(fd) != 0 && !error) error = errno;
    if (!error && ::renameat(fd_, temporary.c_str(), fd_, name.c_str()) != 0) error = errno;
    if (error) {
        ::unlinkat(fd_, temporary.c_str(), 0);
        fail(path_, "cannot write " + name, error);
    }
    // The rename is durable once the folder is. If that fails the file is in place all the same:
    // the caller must know (NotDurableError), since undoing the write is no longer possible.
    if (::fsync(fd_) != 0 && errno != EINVAL)
        throw NotDurableError(path_.string(), "cannot sync the folder after writing " + name + ": " + std::strerror(errno));
    return FileRecord{name, size, checksum.hex()};
}

void OutputDirectory::probeWritable() {
    std::string probe;
    const int fd = createTemporary("write-test", probe);
    if (fd < 0) failChoosing(path_, "the output folder is not writable", errno);
    ::close(fd);
    ::unlinkat(fd_, probe.c_str(), 0);
}

bool OutputDirectory::remove(const std::string& name) {
    if (::unlinkat(fd_, name.c_str(), 0) == 0) return true;
    if (errno == ENOENT) return false;
    fail(path_, "cannot remove " + name, errno);
}

size_t OutputDirectory::removeStaleTemporaries() {
    size_t removed = 0;
    for (const std::string& name : names())
        if (isTemporaryName(name) && ::unlinkat(fd_, name.c_str(), 0) == 0) ++removed;
    return removed;
}

std::vector<std::string> OutputDirectory::names() const {
    // Through a duplicate of the handle: the same folder, whatever its path names by now.
    const int fd = ::openat(fd_, ".", O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    DIR* dir = fd < 0 ? nullptr : ::fdopendir(fd);
    if (!dir) {
        const int error = errno;
        if (fd >= 0) ::close(fd);
        throw InputError(path_.string(), "--out", std::string("cannot read the output folder: ") + std::strerror(error));
    }
    std::vector<std::string> names;
    while (const dirent* entry = ::readdir(dir)) {
        const std::string name = entry->d_name;
        if (name != "." && name != "..") names.push_back(name);
    }
    ::closedir(dir);
    std::sort(names.begin(), names.end());
    return names;
}

FileRecord writeFileAtomically(const fs::path& path, std::string_view bytes) {
    OutputDirectory folder(path.has_parent_path() ? path.parent_path() : fs::path("."));
    return folder.write(path.filename().string(), bytes);
}

}  // namespace qsgi
