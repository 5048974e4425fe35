#include "output/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace qsgi {

namespace {

constexpr const char* kTemporaryMarker = ".qsgi-tmp";

// fsync of a file or folder by path; `what` names it in the error.
void syncPath(const std::filesystem::path& path, int flags) {
    const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
    if (fd < 0) throw std::runtime_error("cannot open " + path.string() + " to sync it: " + std::strerror(errno));
    const int result = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    if (result != 0) throw std::runtime_error("syncing " + path.string() + " failed: " + std::strerror(error));
}

}  // namespace

AtomicFile::AtomicFile(std::filesystem::path finalPath) : finalPath_(std::move(finalPath)) {
    tempPath_ = finalPath_;
    tempPath_.replace_filename(finalPath_.stem().string() + kTemporaryMarker + finalPath_.extension().string());
}

void AtomicFile::removeStaleTemporaries(const std::filesystem::path& folder) {
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
        if (entry.path().filename().string().find(kTemporaryMarker) == std::string::npos) continue;
        std::error_code ignored;
        std::filesystem::remove(entry.path(), ignored);
    }
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    stream_.close();
    std::error_code ec;
    std::filesystem::remove(tempPath_, ec);
}

std::ofstream& AtomicFile::stream() {
    if (!stream_.is_open()) {
        stream_.open(tempPath_, std::ios::binary | std::ios::trunc);
        if (!stream_) throw std::runtime_error("cannot write " + tempPath_.string());
    }
    return stream_;
}

void AtomicFile::commit() {
    if (stream_.is_open()) {
        stream_.flush();
        const bool ok = bool(stream_);
        stream_.close();
        if (!ok) throw std::runtime_error("writing " + tempPath_.string() + " failed (disk full?)");
    }
    syncPath(tempPath_, O_RDONLY);
    std::error_code ec;
    std::filesystem::rename(tempPath_, finalPath_, ec);
    if (ec) throw std::runtime_error("cannot rename " + tempPath_.string() + " to " + finalPath_.string() + ": " + ec.message());
    committed_ = true;
    const std::filesystem::path folder = finalPath_.has_parent_path() ? finalPath_.parent_path() : ".";
    syncPath(folder, O_RDONLY | O_DIRECTORY);
}

}  // namespace qsgi
