// Reads a JSON input file; any failure (unreadable, malformed, numbers out of range) becomes an
// InputError naming the file and the byte where parsing stopped.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace qsgi {

nlohmann::json readJsonFile(const std::string& path);

}  // namespace qsgi
