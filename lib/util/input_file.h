// The one rule every file qsgi reads goes through (issue 48): the scene and its buffers and
// textures, an environment map, a transform file, a config, a PLY given to compare. A path must
// name a regular file — a directory, a device (/dev/zero never ends), a pipe (whose open waits for
// a writer) or a socket is refused by its kind — of at most a size the reader states, and it is
// opened without blocking and checked on the open descriptor (fstat), so that what is read is
// what was checked, and read to the size checked and no further.
#pragma once

#include <cstdint>
#include <string>

namespace qsgi {

// The most bytes qsgi reads of an image, a texture or an environment map (tinygltf hands image
// bytes on with an int size), and of a glTF buffer (glTF's limit for a binary glTF).
constexpr uint64_t kMaxImageFileBytes = uint64_t(1) << 31;
constexpr uint64_t kMaxBufferFileBytes = uint64_t(1) << 32;

class InputFile {
public:
    // Opens `path` under the rule; throws InputError(path, "", why not) — "no such file", "is a
    // directory, not <what>", "is a named pipe, not a regular file", "is a device, …", "is N
    // bytes, more than the M qsgi reads for <what>". limit: the most bytes the reader takes; what:
    // what the file should be, for messages ("a glTF file", "an environment map").
    InputFile(const std::string& path, uint64_t limit, const std::string& what);
    ~InputFile();
    InputFile(const InputFile&) = delete;
    InputFile& operator=(const InputFile&) = delete;

    uint64_t size() const { return size_; }
    // The whole file, as its size was when opened (throws InputError if it cannot be read so far).
    std::string readAll();

    // Why `path` cannot be read under the rule, or "" (then `size` holds its size): what a reader
    // that reports through another channel (tinygltf's file callbacks) says. Opens and closes it.
    static std::string problem(const std::string& path, uint64_t limit, const std::string& what, uint64_t& size);

private:
    InputFile() = default;
    // Opens into fd_ and size_; returns why not ("" when open).
    std::string open(const std::string& path, uint64_t limit, const std::string& what);

    std::string path_;
    int fd_ = -1;
    uint64_t size_ = 0;
};

// Reads the whole file at `path` under the rule (InputFile).
std::string readInputFile(const std::string& path, uint64_t limit, const std::string& what);

}  // namespace qsgi
