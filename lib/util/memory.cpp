#include "util/memory.h"

#include <unistd.h>

#include <cstdio>

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

void refuseBeyondMemory(uint64_t bytes, const std::string& file, const std::string& place, const std::string& what) {
    const uint64_t available = physicalMemoryBytes();
    if (bytes > available)
        throw InputError(file, place, what + " would need " + formatBytes(bytes) + ", more than the " +
                                          formatBytes(available) + " of memory this machine has");
}

}  // namespace qsgi
