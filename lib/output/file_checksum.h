// Checksums of what qsgi writes, and the check that a file in the output folder is still what
// timing.json says it wrote. XXH3 (Debian's libxxhash) reads at memory speed; it catches a
// truncated, overwritten or replaced file, not a writer who also edits timing.json (it is a
// checksum, not a signature).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "util/file_record.h"

namespace qsgi {

// XXH3 64-bit of `bytes` as 16 lowercase hex digits.
std::string xxh3Hex(std::string_view bytes);

// The same checksum of bytes that arrive in pieces (a file written as it is made).
class Xxh3Stream {
public:
    Xxh3Stream();
    ~Xxh3Stream();
    Xxh3Stream(const Xxh3Stream&) = delete;
    Xxh3Stream& operator=(const Xxh3Stream&) = delete;
    void update(std::string_view bytes);
    std::string hex() const;  // of everything so far: xxh3Hex of the pieces joined

private:
    struct State;
    std::unique_ptr<State> state_;
};

// Why the file `record.name` in the folder open as `folderFd` is not the one recorded: missing, a
// symbolic link, not a regular file, another size, another checksum. nullopt when it matches.
// Never follows a link at the name. A file that cannot be read (permissions, an I/O error) proves
// nothing either way: throws EnvironmentError naming it, rather than calling it damaged.
std::optional<std::string> fileMismatch(int folderFd, const FileRecord& record, const std::string& folderName);

}  // namespace qsgi
