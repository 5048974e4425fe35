#include "output/atomic_file.h"

#include <stdexcept>
#include <system_error>

namespace qsgi {

AtomicFile::AtomicFile(std::filesystem::path finalPath) : finalPath_(std::move(finalPath)) {
    tempPath_ = finalPath_;
    tempPath_.replace_filename(finalPath_.stem().string() + ".tmp" + finalPath_.extension().string());
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
    std::error_code ec;
    std::filesystem::rename(tempPath_, finalPath_, ec);
    if (ec) throw std::runtime_error("cannot rename " + tempPath_.string() + " to " + finalPath_.string() + ": " + ec.message());
    committed_ = true;
}

}  // namespace qsgi
