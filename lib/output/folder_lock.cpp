#include "output/folder_lock.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>

#include "util/error.h"

namespace qsgi {

namespace {

std::string holderLine(const std::string& what) {
    char host[256] = "unknown";
    ::gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = 0;
    char since[32] = "";
    const std::time_t now = std::time(nullptr);
    std::tm utc{};
    ::gmtime_r(&now, &utc);
    std::strftime(since, sizeof since, "%Y-%m-%dT%H:%M:%SZ", &utc);
    return "pid " + std::to_string(::getpid()) + " on host " + host + " since " + since + " (" + what + ")\n";
}

// The holder's line, for the message: the first line, printable bytes only, at most 200.
std::string readHolder(int fd) {
    char text[256];
    const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
    std::string line;
    for (ssize_t i = 0; i < n && text[i] != '\n' && line.size() < 200; ++i)
        if (text[i] >= 32 && text[i] < 127) line += text[i];
    return line.empty() ? "a process that has not written its name yet" : line;
}

// Opens the lock file: read-write, or read-only where another user made it (flock works on either),
// never through a link planted at the name (unlinked: the link, not its target) and never anything
// but a regular file. Sets `writable`.
int openLockFile(const OutputDirectory& folder, bool& writable) {
    const std::string where = folder.path().string(), file = where + "/" + FolderLock::kFileName;
    for (int attempt = 0;; ++attempt) {
        writable = true;
        int fd = ::openat(folder.fd(), FolderLock::kFileName, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0644);
        if (fd < 0 && errno == EACCES) {
            writable = false;
            fd = ::openat(folder.fd(), FolderLock::kFileName, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
        }
        if (fd >= 0) return fd;
        if (errno == ELOOP && attempt < 3 && ::unlinkat(folder.fd(), FolderLock::kFileName, 0) == 0) continue;
        if (errno == EACCES || errno == EPERM || errno == EROFS)
            throw InputError(file, "--out", std::string("cannot open the folder's lock file: ") + std::strerror(errno));
        if (errno == EISDIR || errno == ELOOP)
            throw InputError(file, "", "is not qsgi's lock file (a folder or a link stands there); remove it");
        throw EnvironmentError(where, std::string("cannot make the lock file ") + FolderLock::kFileName + ": " + std::strerror(errno));
    }
}

// Whether `fd` is still the file at the lock's name: another run may have unlinked a planted
// link and made its own file between our open and our flock.
bool stillAtTheName(const OutputDirectory& folder, int fd) {
    struct stat opened {}, named {};
    return ::fstat(fd, &opened) == 0 && ::fstatat(folder.fd(), FolderLock::kFileName, &named, AT_SYMLINK_NOFOLLOW) == 0 &&
           opened.st_dev == named.st_dev && opened.st_ino == named.st_ino;
}

}  // namespace

FolderLock::FolderLock(const OutputDirectory& folder, const std::string& what) {
    const std::string where = folder.path().string();
    bool writable = true;
    for (int attempt = 0;; ++attempt) {
        fd_ = openLockFile(folder, writable);
        struct stat status {};
        if (::fstat(fd_, &status) != 0 || !S_ISREG(status.st_mode)) {
            ::close(fd_);
            fd_ = -1;
            throw InputError(where + "/" + kFileName, "", "is not qsgi's lock file (not a regular file); remove it");
        }
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
            const int error = errno;
            if (error == EWOULDBLOCK) {
                const std::string holder = readHolder(fd_);
                ::close(fd_);
                fd_ = -1;
                throw FolderBusyError(where + ": another run is writing into this folder (" + holder +
                                      "); wait for it to end, or render into another folder");
            }
            unguardedReason_ = std::string("cannot lock ") + where + "/" + kFileName + " (" + std::strerror(error) +
                               "): this file system does not lock, so nothing stops a second run from writing into the "
                               "folder at the same time, and stale temporaries are left in place";
            return;
        }
        if (stillAtTheName(folder, fd_)) break;
        ::close(fd_);
        fd_ = -1;
        if (attempt > 3) throw FolderBusyError(where + ": the lock file keeps being replaced; is another run starting?");
    }
    held_ = true;
    // A lock file with another name elsewhere (a hard link planted at ours) is locked but left
    // as it is: truncating it would change that other file. One another user made is read-only.
    struct stat status {};
    if (!writable || ::fstat(fd_, &status) != 0 || status.st_nlink > 1) return;
    const std::string line = holderLine(what);
    // Best effort: the line only names the holder in another run's message.
    [[maybe_unused]] const bool named =
        ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, line.data(), line.size(), 0) == ssize_t(line.size());
}

FolderLock::~FolderLock() {
    if (fd_ >= 0) ::close(fd_);
}

}  // namespace qsgi
