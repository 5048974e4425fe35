#include "util/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "util/error.h"

namespace qsgi {

uint64_t physicalMemoryBytes() {
    const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || pageSize <= 0) return uint64_t(1) << 40;
    return uint64_t(pages) * uint64_t(pageSize);
}

std::string formatBytes(uint64_t bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    double value = double(bytes);
    int unit = 0;
    while (value >= 1024 && unit < 6) {
        value /= 1024;
        ++unit;
    }
    char text[32];
    std::snprintf(text, sizeof text, unit == 0 ? "%.0f %s" : "%.1f %s", value, units[unit]);
    return text;
}

namespace {

// A number from a control-group file ("max" and unreadable files: no limit).
uint64_t cgroupLimit(const std::string& path) {
    std::ifstream in(path);
    std::string text;
    if (!(in >> text) || text == "max" || text.find_first_not_of("0123456789") != std::string::npos) return UINT64_MAX;
    try {
        return std::stoull(text);
    } catch (const std::exception&) {
        return UINT64_MAX;
    }
}

// The memory limit of this process's control group: cgroup v2's memory.max (the line "0::/path"
// of /proc/self/cgroup), else cgroup v1's memory.limit_in_bytes (the "memory" line's path).
uint64_t controlGroupLimit() {
    std::ifstream groups("/proc/self/cgroup");
    std::string line;
    uint64_t limit = UINT64_MAX;
    while (std::getline(groups, line)) {
        if (line.rfind("0::", 0) == 0) {
            limit = std::min(limit, cgroupLimit("/sys/fs/cgroup" + line.substr(3) + "/memory.max"));
        } else {
            const size_t colon = line.find(':'), second = line.find(':', colon + 1);
            if (colon == std::string::npos || second == std::string::npos) continue;
            const std::string controllers = line.substr(colon + 1, second - colon - 1);
            if (("," + controllers + ",").find(",memory,") == std::string::npos) continue;
            const std::string path = line.substr(second + 1);
            limit = std::min(limit, cgroupLimit("/sys/fs/cgroup/memory" + path + "/memory.limit_in_bytes"));
            limit = std::min(limit, cgroupLimit("/sys/fs/cgroup/memory/memory.limit_in_bytes"));
        }
    }
    return limit;
}

MemoryLimit readUsableMemory() {
    MemoryLimit limit{physicalMemoryBytes(), "this machine has"};
    auto consider = [&](uint64_t bytes, const char* source) {
        if (bytes < limit.bytes) limit = {bytes, source};
    };
    rlimit r{};
    if (getrlimit(RLIMIT_AS, &r) == 0 && r.rlim_cur != RLIM_INFINITY) consider(uint64_t(r.rlim_cur), "ulimit -v allows this process");
    if (getrlimit(RLIMIT_DATA, &r) == 0 && r.rlim_cur != RLIM_INFINITY) consider(uint64_t(r.rlim_cur), "ulimit -d allows this process");
    consider(controlGroupLimit(), "its control group (a container's or a job's limit) allows this process");
    return limit;
}

}  // namespace

MemoryLimit usableMemory() {
    // Read once: the limits do not change under a running process, and every accessor and photon
    // count is checked against them (reading /proc and /sys each time made the fuzzers' loads
    // ten times slower).
    static const MemoryLimit limit = readUsableMemory();
    return limit;
}

void refuseBeyondMemory(uint64_t bytes, const std::string& file, const std::string& place, const std::string& what) {
    const MemoryLimit available = usableMemory();
    if (bytes > available.bytes)
        throw InputError(file, place, what + " would need " + formatBytes(bytes) + ", more than the " +
                                          formatBytes(available.bytes) + " of memory " + available.source);
}

}  // namespace qsgi
