// The one rule every file qsgi reads goes through: the scene and its buffers and textures, an
// environment map, a transform file, a config, a PLY given to compare. A path must name a regular
// file — a directory, a device (/dev/zero never ends), a pipe (whose open waits for a writer) or a
// socket is refused by its kind — of at most a size the reader states, and it is opened without
// blocking and checked on the open descriptor (fstat). Every reader then takes its bytes from that
// same descriptor, once: the file is opened once per run, so what is read is what was checked (a
// second open by path could find another file there), and it is read to the size checked and no
// further.
#pragma once

#include <cstdint>
#include <istream>
#include <memory>
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

    const std::string& path() const { return path_; }
    uint64_t size() const { return size_; }
    // The whole file, as its size was when opened (throws InputError if it cannot be read so far).
    std::string readAll();
    // The same into `destination`, which holds size() bytes: for a reader that keeps the bytes in
    // a container of its own (tinygltf's buffers), so that they are not read into one and copied.
    void readAllInto(void* destination);
    // The file's bytes from its start, as a seekable stream that ends at size(), for readers that
    // parse as they go (a PLY of many vertices is not held twice). Reading past a shrunk end or a
    // disk error throws InputError through the stream (its exceptions include badbit); a short
    // read at size() is an ordinary end of file. Independent of readAll, which reads from the
    // start whatever the stream has read.
    std::istream& stream();

private:
    class Buffer;
    // Reads `bytes` at `offset` into `into`, all of them or throws InputError.
    void readAt(char* into, size_t bytes, uint64_t offset) const;

    std::string path_;
    int fd_ = -1;
    uint64_t size_ = 0;
    std::unique_ptr<Buffer> buffer_;  // made by stream()
    std::unique_ptr<std::istream> stream_;
};

// Reads the whole file at `path` under the rule (InputFile).
std::string readInputFile(const std::string& path, uint64_t limit, const std::string& what);

}  // namespace qsgi
