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

}  // namespace

FolderLock::FolderLock(const OutputDirectory& folder, const std::string& what) {
    const std::string where = folder.path().string();
    for (int attempt = 0; fd_ < 0; ++attempt) {
        fd_ = ::openat(folder.fd(), kFileName, O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0644);
        if (fd_ >= 0) break;
        // A symbolic link at the name is not ours: unlinked (the link, not its target), then the
        // file made afresh.
        if (errno == ELOOP && attempt == 0 && ::unlinkat(folder.fd(), kFileName, 0) == 0) continue;
        if (errno == EACCES || errno == EPERM || errno == EROFS)
            throw InputError(where, "--out", std::string("the output folder is not writable: ") + std::strerror(errno));
        if (errno == EISDIR || errno == ELOOP)
            throw InputError(where + "/" + kFileName, "", "is not qsgi's lock file (a folder or a link stands there); remove it");
        throw EnvironmentError(where, std::string("cannot make the lock file ") + kFileName + ": " + std::strerror(errno));
    }
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
    held_ = true;
    // A lock file with another name elsewhere (a hard link planted at ours) is locked but left
    // as it is: truncating it would change that other file.
    if (status.st_nlink > 1) return;
    const std::string line = holderLine(what);
    // Best effort: the line only names the holder in another run's message.
    [[maybe_unused]] const bool named =
        ::ftruncate(fd_, 0) == 0 && ::pwrite(fd_, line.data(), line.size(), 0) == ssize_t(line.size());
}

FolderLock::~FolderLock() {
    if (fd_ >= 0) ::close(fd_);
}

}  // namespace qsgi
