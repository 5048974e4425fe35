// A 64-bit digest as text: the form timing.json's checksums and the resume fingerprint are
// written in, so both must keep it (older folders are compared against it byte for byte).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>

namespace qsgi {

// `value` as 16 lowercase hex digits, zero-padded.
inline std::string hex(uint64_t value) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
    return text;
}

}  // namespace qsgi
