#include "output/usd_identifiers.h"

namespace qsgi {

std::string usdIdentifier(const std::string& name, const std::string& fallback) {
    if (name.empty()) return fallback;
    std::string id;
    id.reserve(name.size() + 1);
    if (name[0] >= '0' && name[0] <= '9') id += '_';
    for (const char c : name) {
        const bool word = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
        id += word ? c : '_';
    }
    return id;
}

std::string UniqueNames::claim(const std::string& identifier) {
    if (taken_.insert(identifier).second) return identifier;
    for (size_t n = 1;; ++n) {
        std::string candidate = identifier + "_" + std::to_string(n);
        if (taken_.insert(candidate).second) return candidate;
    }
}

}  // namespace qsgi
