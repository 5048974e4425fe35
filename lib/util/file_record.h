// One file of a frame as timing.json records it (docs/design.md §7): its name in the output folder,
// its size and the XXH3-64 checksum of its bytes. What --resume and the Slurm merge verify a
// frame's files against before they trust them.
#pragma once

#include <cstdint>
#include <string>

namespace qsgi {

struct FileRecord {
    std::string name;    // "frame_0003.ply": a name in the output folder, no path
    uint64_t bytes = 0;  // the file's size
    std::string xxh3;    // XXH3 64-bit, seed 0, of the whole file: 16 lowercase hex digits
};

}  // namespace qsgi
