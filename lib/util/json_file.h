// Reads a JSON input file; any failure (unreadable, malformed, numbers out of range) becomes an
// InputError naming the file and the byte where parsing stopped.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace qsgi {

// A JSON file of qsgi's own (a config, a transform file). Besides syntax it refuses a key given
// twice in one object (JSON readers silently keep one of them) and nesting deeper than
// kMaxJsonDepth; it is read under the one opening rule (util/input_file.h): a directory, a
// device or a pipe is refused by its kind.
nlohmann::json readJsonFile(const std::string& path);
// The same rules for a JSON file's bytes already read (`path` names it in messages): a reader
// that keeps the bytes too (the fingerprint of a transform file) reads the file once.
nlohmann::json parseJsonFile(const std::string& path, const std::string& text);

// Nesting deeper than this is refused before any parser sees it: recursive readers (tinygltf's
// copy of extras) overflow the stack around 10^4–10^5 levels, and no scene needs more than a few.
constexpr size_t kMaxJsonDepth = 256;
// The largest JSON file read (a config, a transform file of 10^5 frames is a few MiB): its parsed
// form takes several times its bytes.
constexpr uint64_t kMaxJsonFileBytes = uint64_t(256) << 20;
// Throws InputError(path, "byte N", …) at the first bracket nested deeper than kMaxJsonDepth;
// `byteOffset` is added to N (the JSON chunk's place in a GLB).
void refuseDeepNesting(const std::string& text, const std::string& path, size_t byteOffset = 0);

// Throws InputError(file, place.key, "unknown key (did you mean …?)") for a key of the object `j`
// that is not in `known`. Keys starting with "_", and "comment", are notes for people.
void refuseUnknownKeys(const nlohmann::json& j, const std::vector<std::string>& known, const std::string& file,
                       const std::string& place);

// A file name as JSON records it. Names are bytes on Linux and JSON text is UTF-8: a name that
// is UTF-8 is a string; any other is {"text": the name with U+FFFD for each byte that does not
// decode, for people, "hex": its exact bytes in hex, for programs} (docs/design.md §7), so
// timing.json and inspect record every name losslessly.
nlohmann::json pathJson(const std::string& name);

}  // namespace qsgi
