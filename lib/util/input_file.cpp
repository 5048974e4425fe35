#include "util/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "util/error.h"
#include "util/memory.h"

namespace qsgi {

namespace {
// What a file that is not regular is, by its mode.
std::string kindOf(mode_t mode, const std::string& what) {
    if (S_ISDIR(mode)) return "is a directory, not " + what;
    if (S_ISFIFO(mode)) return "is a named pipe, not a regular file";
    if (S_ISSOCK(mode)) return "is a socket, not a regular file";
    if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
    return "is not a regular file";
}
}  // namespace

std::string InputFile::open(const std::string& path, uint64_t limit, const std::string& what) {
    path_ = path;
    // O_NONBLOCK: opening a pipe with no writer returns at once instead of waiting; the kind is
    // then refused from the descriptor's own status.
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    if (fd_ < 0) {
        const int error = errno;
        if (error == ENOENT) return "no such file";
        struct stat status {};
        // A socket, or a device node with no device behind it, cannot be opened: named by its kind.
        if (error == ENXIO && ::stat(path.c_str(), &status) == 0) return kindOf(status.st_mode, what);
        return std::string("cannot be opened for reading (") + std::strerror(error) + ")";
    }
    struct stat status {};
    if (::fstat(fd_, &status) != 0) return std::string("cannot be read (") + std::strerror(errno) + ")";
    if (!S_ISREG(status.st_mode)) return kindOf(status.st_mode, what);
    size_ = uint64_t(status.st_size);
    if (size_ > limit)
        return "is " + std::to_string(size_) + " bytes, more than the " + formatBytes(limit) + " qsgi reads for " + what;
    return "";
}

InputFile::InputFile(const std::string& path, uint64_t limit, const std::string& what) {
    const std::string why = open(path, limit, what);
    if (!why.empty()) {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
        throw InputError(path, "", why);
    }
}

InputFile::~InputFile() {
    if (fd_ >= 0) ::close(fd_);
}

std::string InputFile::readAll() {
    std::string bytes(size_t(size_), '\0');
    size_t done = 0;
    while (done < bytes.size()) {
        const ssize_t got = ::read(fd_, &bytes[done], bytes.size() - done);
        if (got < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (got == 0) throw InputError(path_, "", "became shorter while it was read");
        if (got < 0) throw InputError(path_, "", std::string("cannot be read (") + std::strerror(errno) + ")");
        done += size_t(got);
    }
    return bytes;
}

std::string InputFile::problem(const std::string& path, uint64_t limit, const std::string& what, uint64_t& size) {
    InputFile file;
    std::string why = file.open(path, limit, what);
    size = file.size_;
    return why;
}

std::string readInputFile(const std::string& path, uint64_t limit, const std::string& what) {
    InputFile file(path, limit, what);
    return file.readAll();
}

}  // namespace qsgi
