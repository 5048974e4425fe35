#include "util/json_file.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>

#include "util/error.h"
#include "util/nearest_name.h"

namespace qsgi {

void refuseDeepNesting(const std::string& text, const std::string& path, size_t byteOffset) {
    size_t depth = 0;
    bool inString = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (inString) {
            if (c == '\\') ++i;
            else if (c == '"') inString = false;
        } else if (c == '"') {
            inString = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth)
                throw InputError(path, "byte " + std::to_string(i + byteOffset),
                                 "JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
}

nlohmann::json readJsonFile(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) throw InputError(path, "", "is a directory, not a JSON file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", "cannot be opened for reading");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw InputError(path, "", "cannot be read");
    refuseDeepNesting(text, path);
    // One set of keys per object being read; a second of the same name is refused.
    std::vector<std::set<std::string>> keys;
    auto refuseDuplicates = [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        using Event = nlohmann::json::parse_event_t;
        if (event == Event::object_start) keys.emplace_back();
        else if (event == Event::object_end && !keys.empty()) keys.pop_back();
        else if (event == Event::key && !keys.empty() && !keys.back().insert(parsed.get<std::string>()).second)
            throw InputError(path, parsed.get<std::string>(),
                             "this key is given twice in one object (JSON keeps only one of them: remove the other)");
        return true;
    };
    try {
        return nlohmann::json::parse(text, refuseDuplicates);
    } catch (const nlohmann::json::parse_error& e) {
        throw InputError(path, "byte " + std::to_string(e.byte), "not valid JSON");
    } catch (const nlohmann::json::exception& e) {
        // e.g. out_of_range 406: a number too large for a double (1e999)
        std::string what = e.what();
        const auto bracket = what.find("] ");
        throw InputError(path, "", "not usable JSON: " + (bracket == std::string::npos ? what : what.substr(bracket + 2)));
    }
}

void refuseUnknownKeys(const nlohmann::json& j, const std::vector<std::string>& known, const std::string& file,
                       const std::string& place) {
    for (auto it = j.begin(); it != j.end(); ++it) {
        const std::string& key = it.key();
        if (std::find(known.begin(), known.end(), key) != known.end() || key.rfind("_", 0) == 0 || key == "comment")
            continue;
        throw InputError(file, place.empty() ? key : place + "." + key, "unknown key" + didYouMean(key, known));
    }
}

}  // namespace qsgi
