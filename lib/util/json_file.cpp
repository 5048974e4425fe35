#include "util/json_file.h"

#include <fstream>

#include "util/error.h"

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

}  // namespace qsgi
