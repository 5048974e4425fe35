// Reads a JSON input file; any failure (unreadable, malformed, numbers out of range) becomes an
// InputError naming the file and the byte where parsing stopped.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace qsgi {

nlohmann::json readJsonFile(const std::string& path);

// Throws InputError(file, place.key, "unknown key (did you mean …?)") for a key of the object `j`
// that is not in `known`. Keys starting with "_", and "comment", are notes for people.
void refuseUnknownKeys(const nlohmann::json& j, const std::vector<std::string>& known, const std::string& file,
                       const std::string& place);

}  // namespace qsgi
