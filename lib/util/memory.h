// How much memory this machine has, so that a request that cannot fit (a huge accessor, billions of
// photons) is refused with the numbers before anything is allocated, instead of dying in the
// allocator or the OOM killer hours later.
#pragma once

#include <cstdint>
#include <string>

namespace qsgi {

// Physical memory of the machine, in bytes (sysconf); a large fallback if it cannot be read.
uint64_t physicalMemoryBytes();

// The memory this process may use: the least of the machine's memory, the address-space and data
// limits (ulimit -v, ulimit -d) and the memory limit of its control group (a container's, a Slurm
// job's), with the name of the one that binds ("this machine has", "ulimit -v allows", …).
struct MemoryLimit {
    uint64_t bytes;
    std::string source;
};
MemoryLimit usableMemory();

// "48.0 GiB", "512 MiB", "12 KiB", "100 B".
std::string formatBytes(uint64_t bytes);

// Throws InputError(file, place, "<what> would need X, more than the Y of memory <source>") when
// bytes exceeds usableMemory().
void refuseBeyondMemory(uint64_t bytes, const std::string& file, const std::string& place, const std::string& what);

// a*b, saturating at UINT64_MAX instead of wrapping.
inline uint64_t saturatingMultiply(uint64_t a, uint64_t b) {
    return (a != 0 && b > UINT64_MAX / a) ? UINT64_MAX : a * b;
}

// a+b, saturating at UINT64_MAX instead of wrapping (a hostile byteOffset near 2^64 must not wrap
// a range check around to pass).
inline uint64_t saturatingAdd(uint64_t a, uint64_t b) { return b > UINT64_MAX - a ? UINT64_MAX : a + b; }

}  // namespace qsgi
