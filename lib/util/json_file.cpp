#include "util/json_file.h"

#include <algorithm>
#include <fstream>

#include "util/error.h"
#include "util/nearest_name.h"

namespace qsgi {

nlohmann::json readJsonFile(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(path, "", "cannot be opened for reading");
    try {
        return nlohmann::json::parse(in);
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
