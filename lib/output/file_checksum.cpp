#include "output/file_checksum.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <new>
#include <vector>

#include "util/error.h"
#include "util/hex.h"

namespace qsgi {

namespace {
struct StateFree {
    void operator()(XXH3_state_t* state) const { XXH3_freeState(state); }
};
}  // namespace

std::string xxh3Hex(std::string_view bytes) { return hex(XXH3_64bits(bytes.data(), bytes.size())); }

struct Xxh3Stream::State {
    std::unique_ptr<XXH3_state_t, StateFree> xxh{XXH3_createState()};
};

Xxh3Stream::Xxh3Stream() : state_(std::make_unique<State>()) {
    if (!state_->xxh) throw std::bad_alloc();
    XXH3_64bits_reset(state_->xxh.get());
}
Xxh3Stream::~Xxh3Stream() = default;

void Xxh3Stream::update(std::string_view bytes) { XXH3_64bits_update(state_->xxh.get(), bytes.data(), bytes.size()); }

std::string Xxh3Stream::hex() const { return qsgi::hex(XXH3_64bits_digest(state_->xxh.get())); }

std::optional<std::string> fileMismatch(int folderFd, const FileRecord& record, const std::string& folderName) {
    auto unreadable = [&](int error) {
        return EnvironmentError(folderName, "cannot read " + record.name + " to verify it: " + std::strerror(error));
    };
    struct stat link {};
    if (::fstatat(folderFd, record.name.c_str(), &link, AT_SYMLINK_NOFOLLOW) != 0) {
        if (errno == ENOENT) return std::string("missing");
        throw unreadable(errno);
    }
    if (S_ISLNK(link.st_mode)) return "is a symbolic link, not a file qsgi wrote";
    if (!S_ISREG(link.st_mode)) return "is not a regular file";
    if (uint64_t(link.st_size) != record.bytes)
        return "has " + std::to_string(link.st_size) + " bytes, timing.json says " + std::to_string(record.bytes);
    const int fd = ::openat(folderFd, record.name.c_str(), O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) throw unreadable(errno);
    Xxh3Stream checksum;
    std::vector<char> buffer(1 << 20);
    uint64_t total = 0;
    for (;;) {
        const ssize_t n = ::read(fd, buffer.data(), buffer.size());
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const int error = errno;
            ::close(fd);
            throw unreadable(error);
        }
        if (n == 0) break;
        checksum.update(std::string_view(buffer.data(), size_t(n)));
        total += uint64_t(n);
    }
    ::close(fd);
    if (total != record.bytes) return "changed while being checked";
    if (checksum.hex() != record.xxh3) return "has other bytes than qsgi wrote (checksum differs)";
    return std::nullopt;
}

}  // namespace qsgi
