#include "util/input_file.h"
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

namespace {

// A SAX pass that only looks at keys: one set per object being read, a second key of the same
// name is refused. (nlohmann's DOM callback could do it, but its end_object scans the enclosing
// array for discarded values, which makes a file of many frames quadratic.)
class DuplicateKeyFinder : public nlohmann::json_sax<nlohmann::json> {
public:
    explicit DuplicateKeyFinder(const std::string& path) : path_(path) {}
    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override {
        keys_.emplace_back();
        return true;
    }
    bool key(string_t& name) override {
        if (!keys_.empty() && !keys_.back().insert(name).second)
            throw InputError(path_, name, "this key is given twice in one object (JSON keeps only one of them: remove the other)");
        return true;
    }
    bool end_object() override {
        if (!keys_.empty()) keys_.pop_back();
        return true;
    }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    // Syntax errors are the DOM parse's to report, with the byte.
    bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override { return false; }

private:
    const std::string& path_;
    std::vector<std::set<std::string>> keys_;
};

}  // namespace

nlohmann::json readJsonFile(const std::string& path) {
    return parseJsonFile(path, readInputFile(path, kMaxJsonFileBytes, "a JSON file"));
}

nlohmann::json parseJsonFile(const std::string& path, const std::string& text) {
    refuseDeepNesting(text, path);
    try {
        DuplicateKeyFinder duplicates(path);
        nlohmann::json::sax_parse(text, &duplicates);
        return nlohmann::json::parse(text);
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

nlohmann::json pathJson(const std::string& name) {
    using nlohmann::json;
    // nlohmann's serializer is the UTF-8 check: strict, it throws on the first invalid byte;
    // with `replace`, it writes U+FFFD for it.
    try {
        (void)json(name).dump();
        return name;
    } catch (const json::type_error&) {
    }
    static constexpr char kDigits[] = "0123456789abcdef";
    std::string hex;
    for (unsigned char c : name) {
        hex += kDigits[c >> 4];
        hex += kDigits[c & 15];
    }
    const std::string quoted = json(name).dump(-1, ' ', false, json::error_handler_t::replace);
    return {{"text", json::parse(quoted).get<std::string>()}, {"hex", hex}};
}

}  // namespace qsgi
