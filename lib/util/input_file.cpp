#include "util/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

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

// Why the descriptor `fd` of `path` (or its open's errno when fd < 0) is not a file to read under
// the rule; "" when it is, its size then in `size`.
std::string openProblem(const std::string& path, int fd, int openError, uint64_t limit, const std::string& what,
                        uint64_t& size) {
    if (fd < 0) {
        if (openError == ENOENT) return "no such file";
        struct stat status {};
        // A socket, or a device node with no device behind it, cannot be opened: named by its kind.
        if (openError == ENXIO && ::stat(path.c_str(), &status) == 0) return kindOf(status.st_mode, what);
        return std::string("cannot be opened for reading (") + std::strerror(openError) + ")";
    }
    struct stat status {};
    if (::fstat(fd, &status) != 0) return std::string("cannot be read (") + std::strerror(errno) + ")";
    if (!S_ISREG(status.st_mode)) return kindOf(status.st_mode, what);
    size = uint64_t(status.st_size);
    if (size > limit)
        return "is " + std::to_string(size) + " bytes, more than the " + formatBytes(limit) + " qsgi reads for " + what;
    return "";
}
}  // namespace

// A stream's buffer over the descriptor: chunks read with pread at the stream's own position, and
// large reads straight into the reader's memory, so the file is neither reopened nor held whole.
class InputFile::Buffer : public std::streambuf {
public:
    explicit Buffer(const InputFile& file) : file_(file), chunk_(size_t(1) << 16) {}

protected:
    int_type underflow() override {
        if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
        if (next_ >= file_.size_) return traits_type::eof();
        const size_t bytes = size_t(std::min<uint64_t>(chunk_.size(), file_.size_ - next_));
        file_.readAt(chunk_.data(), bytes, next_);
        start_ = next_;
        next_ += bytes;
        setg(chunk_.data(), chunk_.data(), chunk_.data() + bytes);
        return traits_type::to_int_type(*gptr());
    }

    std::streamsize xsgetn(char* into, std::streamsize count) override {
        std::streamsize done = 0;
        while (done < count) {
            const std::streamsize buffered = egptr() - gptr();
            if (buffered > 0) {
                const std::streamsize take = std::min(buffered, count - done);
                std::memcpy(into + done, gptr(), size_t(take));
                gbump(int(take));  // at most a chunk
                done += take;
            } else if (uint64_t(count - done) >= chunk_.size()) {
                if (next_ >= file_.size_) break;
                const size_t bytes = size_t(std::min<uint64_t>(uint64_t(count - done), file_.size_ - next_));
                file_.readAt(into + done, bytes, next_);
                next_ += bytes;
                start_ = next_;
                setg(chunk_.data(), chunk_.data(), chunk_.data());
                done += std::streamsize(bytes);
            } else if (underflow() == traits_type::eof()) {
                break;
            }
        }
        return done;
    }

    pos_type seekoff(off_type offset, std::ios_base::seekdir direction, std::ios_base::openmode which) override {
        if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
        const int64_t here = int64_t(start_) + (gptr() - eback());
        const int64_t target = direction == std::ios_base::beg   ? int64_t(offset)
                               : direction == std::ios_base::cur ? here + int64_t(offset)
                                                                 : int64_t(file_.size_) + int64_t(offset);
        if (target < 0) return pos_type(off_type(-1));
        if (uint64_t(target) >= start_ && uint64_t(target) <= next_) {
            setg(eback(), eback() + (uint64_t(target) - start_), egptr());
        } else {
            // Beyond what is buffered (past the end too, as a file stream allows: reads there end).
            start_ = next_ = uint64_t(target);
            setg(chunk_.data(), chunk_.data(), chunk_.data());
        }
        return pos_type(off_type(target));
    }

    pos_type seekpos(pos_type position, std::ios_base::openmode which) override {
        return seekoff(off_type(position), std::ios_base::beg, which);
    }

private:
    const InputFile& file_;
    std::vector<char> chunk_;
    uint64_t start_ = 0;  // the file offset of the buffered chunk's first byte
    uint64_t next_ = 0;   // the file offset just after it
};

InputFile::InputFile(const std::string& path, uint64_t limit, const std::string& what) : path_(path) {
    // O_NONBLOCK: opening a pipe with no writer returns at once instead of waiting; the kind is
    // then refused from the descriptor's own status.
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
    const int openError = errno;
    const std::string why = openProblem(path, fd_, openError, limit, what, size_);
    if (!why.empty()) {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
        throw InputError(path, "", why);
    }
}

InputFile::~InputFile() {
    stream_.reset();
    buffer_.reset();
    if (fd_ >= 0) ::close(fd_);
}

void InputFile::readAt(char* into, size_t bytes, uint64_t offset) const {
    size_t done = 0;
    while (done < bytes) {
        const ssize_t got = ::pread(fd_, into + done, bytes - done, off_t(offset + done));
        if (got < 0 && (errno == EINTR || errno == EAGAIN)) continue;
        if (got == 0) throw InputError(path_, "", "became shorter while it was read");
        if (got < 0) throw InputError(path_, "", std::string("cannot be read (") + std::strerror(errno) + ")");
        done += size_t(got);
    }
}

void InputFile::readAllInto(void* destination) { readAt(static_cast<char*>(destination), size_t(size_), 0); }

std::string InputFile::readAll() {
    std::string bytes(size_t(size_), '\0');
    readAllInto(bytes.data());
    return bytes;
}

std::istream& InputFile::stream() {
    if (!stream_) {
        buffer_ = std::make_unique<Buffer>(*this);
        stream_ = std::make_unique<std::istream>(buffer_.get());
        // The buffer's InputError (a file that shrank, a disk error) reaches the reader whole,
        // instead of looking like the file's end.
        stream_->exceptions(std::ios::badbit);
    }
    return *stream_;
}

std::string readInputFile(const std::string& path, uint64_t limit, const std::string& what) {
    InputFile file(path, limit, what);
    return file.readAll();
}

}  // namespace qsgi
