#include "scene/gltf_document.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include "util/input_file.h"
#include "util/json_file.h"
#include "util/memory.h"

// Part of libtinygltf's exported API, though its header declares it only for the translation
// unit that compiles the implementation.
namespace tinygltf {
std::string base64_encode(unsigned char const* bytes, unsigned int length);
}

namespace qsgi {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr uint32_t kGlbJsonChunk = 0x4E4F534A;  // "JSON"
constexpr uint32_t kGlbBinChunk = 0x004E4942;   // "BIN\0"

unsigned char uchar(char c) { return static_cast<unsigned char>(c); }

uint32_t readU32(const std::string& bytes, size_t offset) {
    uint32_t v;
    std::memcpy(&v, bytes.data() + offset, 4);
    return v;  // GLB is little-endian, as is every machine qsgi builds on
}

void appendU32(std::string& bytes, uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); }

// The container of a .glb: its JSON chunk, and where the chunks after it start.
struct GlbLayout {
    std::string jsonText;
    size_t afterJson = 0;
    int binChunks = 0;
};

GlbLayout readGlbLayout(const std::string& path, const std::string& bytes) {
    if (bytes.size() < 20) throw InputError(path, "GLB header", "the file is too short to be a binary glTF");
    const uint32_t version = readU32(bytes, 4), length = readU32(bytes, 8);
    if (version != 2)
        throw InputError(path, "GLB header", "container version " + std::to_string(version) + " is not 2 (glTF 2.0)");
    if (length != bytes.size())
        throw InputError(path, "GLB header", "declares " + std::to_string(length) + " bytes but the file has " +
                                                 std::to_string(bytes.size()) + " (truncated or padded)");
    const uint32_t jsonLength = readU32(bytes, 12), jsonType = readU32(bytes, 16);
    if (jsonType != kGlbJsonChunk) throw InputError(path, "GLB chunk 0", "is not the JSON chunk");
    if (uint64_t(jsonLength) + 20 > bytes.size())
        throw InputError(path, "GLB chunk 0", "its length " + std::to_string(jsonLength) + " runs past the end of the file");
    // glTF 2.0 (§4.4.3): every chunk is padded to a multiple of 4 bytes, so the next one is aligned.
    if (jsonLength % 4 != 0)
        throw InputError(path, "GLB chunk 0", "its length " + std::to_string(jsonLength) +
                                                  " is not a multiple of 4 (GLB pads chunks with spaces or zeros)");
    int binChunks = 0;
    for (uint64_t at = 20 + uint64_t(jsonLength); at + 8 <= bytes.size();) {
        const uint32_t chunkLength = readU32(bytes, size_t(at));
        binChunks += readU32(bytes, size_t(at) + 4) == kGlbBinChunk;
        if (chunkLength % 4 != 0)
            throw InputError(path, "GLB chunk at byte " + std::to_string(at),
                             "its length " + std::to_string(chunkLength) + " is not a multiple of 4 (GLB pads chunks)");
        at += 8 + uint64_t(chunkLength);
    }
    return {bytes.substr(20, jsonLength), 20 + size_t(jsonLength), binChunks};
}

// "https://host/a.bin" -> "https"; "" for relative paths, data URIs and Windows drive letters.
std::string remoteScheme(const std::string& uri) {
    size_t i = 0;
    while (i < uri.size() && (std::isalnum(static_cast<unsigned char>(uri[i])) || uri[i] == '+' || uri[i] == '-' || uri[i] == '.'))
        ++i;
    if (i < 2 || i >= uri.size() || uri[i] != ':' || !std::isalpha(static_cast<unsigned char>(uri[0]))) return "";
    std::string scheme = uri.substr(0, i);
    for (char& c : scheme) c = char(std::tolower(static_cast<unsigned char>(c)));
    return scheme == "data" || scheme == "file" ? "" : scheme;
}

void checkAsset(const std::string& path, const json& doc) {
    if (!doc.contains("asset") || !doc["asset"].is_object())
        throw InputError(path, "asset", "is missing (every glTF file must state asset.version)");
    const json& asset = doc["asset"];
    auto versionOf = [&](const char* key) -> std::pair<int, int> {
        const std::string place = std::string("asset.") + key;
        if (!asset[key].is_string()) throw InputError(path, place, "must be a string such as \"2.0\"");
        const std::string v = asset[key].get<std::string>();
        const size_t dot = v.find('.');
        auto digits = [](const std::string& s) {
            return !s.empty() && s.size() < 6 && s.find_first_not_of("0123456789") == std::string::npos;
        };
        if (dot == std::string::npos || !digits(v.substr(0, dot)) || !digits(v.substr(dot + 1)))
            throw InputError(path, place, "'" + v + "' is not of the form major.minor");
        return {std::stoi(v.substr(0, dot)), std::stoi(v.substr(dot + 1))};
    };
    if (!asset.contains("version")) throw InputError(path, "asset.version", "is missing (glTF 2.0 files say \"2.0\")");
    const auto version = versionOf("version");
    if (version.first != 2)
        throw InputError(path, "asset.version", "is " + asset["version"].get<std::string>() +
                                                    ": qsgi reads glTF 2.x only");
    if (asset.contains("minVersion")) {
        const auto minVersion = versionOf("minVersion");
        if (minVersion.first != 2 || minVersion.second > 0)
            throw InputError(path, "asset.minVersion", "is " + asset["minVersion"].get<std::string>() +
                                                           ": the file needs features newer than glTF 2.0, which qsgi implements");
    }
}

// Structural rules tinygltf does not enforce, checked on the JSON before it reads anything. The
// glTF 2.0 schema's integer fields that index or measure bytes and elements: each must be an
// integer >= 0 (its "minimum": 0; componentType, mode and target have enumerated values, checked
// where they are read). tinygltf takes a negative byteOffset as 0 in one place and reads before
// the view in another, so every one of them is checked here, before it reads any. An integer
// written as a float (1.0) is an integer to JSON Schema but not to tinygltf, which refuses the
// file: such values are rewritten as integers. Returns whether any was.
bool refuseNegativeIndices(const std::string& path, json& doc) {
    bool rewritten = false;
    static const std::pair<const char*, std::vector<const char*>> kFields[] = {
        {"accessors", {"bufferView", "byteOffset", "count", "sparse.count", "sparse.indices.bufferView",
                       "sparse.indices.byteOffset", "sparse.values.bufferView", "sparse.values.byteOffset"}},
        {"bufferViews", {"buffer", "byteOffset", "byteLength", "byteStride"}},
        {"buffers", {"byteLength"}},
        {"images", {"bufferView"}},
        {"materials", {"pbrMetallicRoughness.baseColorTexture.index", "pbrMetallicRoughness.baseColorTexture.texCoord",
                       "emissiveTexture.index", "emissiveTexture.texCoord"}},
        {"nodes", {"camera", "mesh", "skin"}},
        {"skins", {"inverseBindMatrices", "skeleton"}},
        {"textures", {"source", "sampler"}},
    };
    auto check = [&](json& value, const std::string& place) {
        const bool integralFloat = value.is_number_float() && value.get<double>() >= 0 && value.get<double>() < 9.0e15 &&
                                   std::floor(value.get<double>()) == value.get<double>();
        if (!value.is_number_unsigned() && !integralFloat)
            throw InputError(path, place, value.dump().substr(0, 40) + " is not a non-negative integer below 2^53 (glTF 2.0 requires one)");
        if (integralFloat) {
            value = uint64_t(value.get<double>());
            rewritten = true;
        }
    };
    for (const auto& [array, fields] : kFields) {
        if (!doc.contains(array) || !doc[array].is_array()) continue;
        json& items = doc[array];
        for (size_t i = 0; i < items.size(); ++i) {
            const std::string item = std::string(array) + "[" + std::to_string(i) + "]";
            for (const char* field : fields) {
                json* at = &items[i];
                std::string dotted = field;
                for (size_t start = 0; at && start <= dotted.size();) {
                    const size_t dot = std::min(dotted.find('.', start), dotted.size());
                    const std::string key = dotted.substr(start, dot - start);
                    at = at->is_object() && at->contains(key) ? &(*at)[key] : nullptr;
                    start = dot + 1;
                }
                if (at) check(*at, item + "." + field);
            }
        }
    }
    // Lists of indices: a node's children, a scene's nodes, a skin's joints; a primitive's indices
    // and material, and its attributes' and targets' accessors; an animation's samplers and targets.
    auto checkList = [&](json& list, const std::string& place) {
        if (!list.is_array()) return;
        for (size_t k = 0; k < list.size(); ++k) check(list[k], place + "[" + std::to_string(k) + "]");
    };
    auto each = [&](const char* array, const auto& visit) {
        if (!doc.contains(array) || !doc[array].is_array()) return;
        for (size_t i = 0; i < doc[array].size(); ++i)
            if (doc[array][i].is_object()) visit(doc[array][i], std::string(array) + "[" + std::to_string(i) + "]");
    };
    each("nodes", [&](json& n, const std::string& at) {
        if (n.contains("children")) checkList(n["children"], at + ".children");
        // glTF 2.0 (§5.25): a matrix or TRS properties, not both (tinygltf keeps one silently).
        if (n.contains("matrix") && (n.contains("translation") || n.contains("rotation") || n.contains("scale")))
            throw InputError(path, at, "has both a matrix and translation, rotation or scale (glTF allows one or the other)");
    });
    each("scenes", [&](json& s, const std::string& at) { if (s.contains("nodes")) checkList(s["nodes"], at + ".nodes"); });
    each("skins", [&](json& s, const std::string& at) { if (s.contains("joints")) checkList(s["joints"], at + ".joints"); });
    each("meshes", [&](json& m, const std::string& at) {
        if (!m.contains("primitives") || !m["primitives"].is_array()) return;
        for (size_t p = 0; p < m["primitives"].size(); ++p) {
            json& prim = m["primitives"][p];
            const std::string place = at + ".primitives[" + std::to_string(p) + "]";
            if (!prim.is_object()) continue;
            for (const char* key : {"indices", "material"})
                if (prim.contains(key)) check(prim[key], place + "." + key);
            if (prim.contains("attributes") && prim["attributes"].is_object())
                for (auto it = prim["attributes"].begin(); it != prim["attributes"].end(); ++it)
                    check(it.value(), place + ".attributes." + it.key());
            if (prim.contains("targets") && prim["targets"].is_array())
                for (size_t t = 0; t < prim["targets"].size(); ++t)
                    if (prim["targets"][t].is_object())
                        for (auto it = prim["targets"][t].begin(); it != prim["targets"][t].end(); ++it)
                            check(it.value(), place + ".targets[" + std::to_string(t) + "]." + it.key());
        }
    });
    each("animations", [&](json& a, const std::string& at) {
        if (a.contains("channels") && a["channels"].is_array())
            for (size_t c = 0; c < a["channels"].size(); ++c) {
                json& ch = a["channels"][c];
                const std::string place = at + ".channels[" + std::to_string(c) + "]";
                if (!ch.is_object()) continue;
                if (ch.contains("sampler")) check(ch["sampler"], place + ".sampler");
                if (ch.contains("target") && ch["target"].is_object() && ch["target"].contains("node"))
                    check(ch["target"]["node"], place + ".target.node");
            }
        if (a.contains("samplers") && a["samplers"].is_array())
            for (size_t s = 0; s < a["samplers"].size(); ++s) {
                json& sm = a["samplers"][s];
                if (!sm.is_object()) continue;
                for (const char* key : {"input", "output"})
                    if (sm.contains(key)) check(sm[key], at + ".samplers[" + std::to_string(s) + "]." + key);
            }
    });
    return rewritten;
}

// A data URI need not be base64 (RFC 2397: "data:application/gltf-buffer,%00%01" is the bytes
// 0 1), but tinygltf reads only base64 ones: others are percent-decoded and handed to it as
// base64. Returns whether any was.
bool rewritePlainDataUris(json& doc, const char* array) {
    if (!doc.contains(array) || !doc[array].is_array()) return false;
    bool rewritten = false;
    for (json& item : doc[array]) {
        if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
        const std::string uri = item["uri"];
        const size_t comma = uri.find(',');
        if (uri.rfind("data:", 0) != 0 || comma == std::string::npos) continue;
        const std::string header = uri.substr(0, comma);
        if (header.size() >= 7 && header.compare(header.size() - 7, 7, ";base64") == 0) continue;
        std::string bytes;
        for (size_t i = comma + 1; i < uri.size(); ++i) {
            if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(uchar(uri[i + 1])) && std::isxdigit(uchar(uri[i + 2]))) {
                bytes += char(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
                i += 2;
            } else {
                bytes += uri[i];
            }
        }
        item["uri"] = header + ";base64," +
                      tinygltf::base64_encode(reinterpret_cast<const unsigned char*>(bytes.data()), unsigned(bytes.size()));
        rewritten = true;
    }
    return rewritten;
}

void refuseRemoteUris(const std::string& path, const json& doc, const char* array) {
    if (!doc.contains(array) || !doc[array].is_array()) return;
    for (size_t i = 0; i < doc[array].size(); ++i) {
        const json& item = doc[array][i];
        if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
        const std::string uri = item["uri"].get<std::string>();
        const std::string scheme = remoteScheme(uri);
        if (!scheme.empty())
            throw InputError(path, std::string(array) + "[" + std::to_string(i) + "].uri",
                             "'" + uri.substr(0, 80) + "' is a remote (" + scheme +
                                 ":) URI; qsgi reads local files only (download it and refer to the file)");
    }
}

// Gives every uri-less buffer that is not the GLB's BIN chunk a 1-byte placeholder; returns them.
std::set<int> replaceAbsentBuffers(json& doc, bool binary) {
    std::set<int> absent;
    if (!doc.contains("buffers") || !doc["buffers"].is_array()) return absent;
    json& buffers = doc["buffers"];
    for (size_t i = binary ? 1 : 0; i < buffers.size(); ++i) {
        if (!buffers[i].is_object() || buffers[i].contains("uri")) continue;
        buffers[i]["uri"] = "data:application/octet-stream;base64,AA==";
        buffers[i]["byteLength"] = 1;
        absent.insert(int(i));
    }
    return absent;
}

// GLB lengths are 32-bit, and tinygltf takes sizes as unsigned int.
void refuseBeyondGltfSize(const std::string& path, uint64_t size) {
    if (size >= (uint64_t(1) << 32)) throw InputError(path, "", "is 4 GiB or larger; glTF files are limited to 2^32 bytes");
}

std::string readBytes(const std::string& path) {
    InputFile file(path, UINT64_MAX, "a glTF file");
    refuseBeyondGltfSize(path, file.size());  // before it is read
    return file.readAll();
}

// tinygltf's image callback: nothing is decoded here (see texture_colour.h). The encoded bytes of a
// uri's file are kept, since tinygltf drops them after this call; an embedded image is left in its
// buffer view, which tinygltf has not range-checked yet, so its bytes are not touched here.
bool keepEncodedImage(tinygltf::Image* image, int, std::string*, std::string*, int, int, const unsigned char* bytes,
                      int size, void*) {
    image->as_is = true;
    if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
    return true;
}

// ---- The files a glTF's uris name ----
// tinygltf's own reader opens whatever a path names: a pipe blocks it for ever, and a directory
// opens, seeks to an "end" of 2^63 - 1 and has that many bytes allocated. Its file callbacks are
// replaced by these, which read a file only if it is a regular file of sane size and keep why
// any other was not read, for the messages. Their size limits are util/input_file.h's.

struct UriFiles {
    std::string baseDir;
    std::set<std::string> imagePaths;             // the paths images' uris resolve to
    std::map<std::string, std::string> problems;  // a path not read -> why ("names a directory, …")
    uint64_t heldBytes = 0;                       // what the files read so far hold in the model
};

// A uri as tinygltf turns it into a file name (its dlib::urldecode: %XX is a byte, '+' a space).
std::string uriFileName(const std::string& uri) {
    auto hex = [](char c) {
        return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : 0;
    };
    std::string name;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') {
            name += ' ';
        } else if (uri[i] == '%' && uri.size() > i + 2) {
            name += char((hex(uri[i + 1]) << 4) | hex(uri[i + 2]));
            i += 2;
        } else {
            name += uri[i];
        }
    }
    return name;
}

// The paths tinygltf looks for a uri's file at, in its order: beside the glTF file, then in the
// working directory (its FindFile and JoinPath).
std::vector<std::string> uriFilePaths(const std::string& baseDir, const std::string& uri) {
    const std::string name = uriFileName(uri);
    auto join = [&](const std::string& dir) {
        return dir.empty() ? name : dir.back() == '/' ? dir + name : dir + "/" + name;
    };
    return {join(baseDir), join(".")};
}

// What the one opening rule's `why` (InputFile) says, in the words of a uri: "names a directory,
// not a file", "names no file", "names a file that became shorter while it was read".
std::string uriFileProblem(const std::string& why) {
    if (why == "no such file") return "names no file";
    if (why.rfind("is a", 0) == 0) return "names " + why.substr(3);  // its kind: "names a named pipe, …"
    return "names a file that " + why;
}

// "" if a uri's file of `size` bytes is one to read: 1 to `limit` - 1 bytes, which with what the
// files read before it hold fit in the memory the process may use; else why not.
std::string uriFileSizeProblem(uint64_t size, uint64_t limit, uint64_t heldBytes) {
    if (size == 0) return "names an empty file";
    if (size >= limit)
        return "names a file of " + std::to_string(size) + " bytes, beyond the " +
               (limit == kMaxImageFileBytes ? "2 GiB qsgi reads for an image" : "4 GiB qsgi reads for a buffer");
    const MemoryLimit memory = usableMemory();
    const uint64_t held = saturatingAdd(heldBytes, size);
    if (held > memory.bytes)
        return "names a file of " + std::to_string(size) + " bytes: with the files read before it, the scene's buffers "
               "and images would hold " + formatBytes(held) + ", more than the " + formatBytes(memory.bytes) +
               " of memory " + memory.source;
    return "";
}

bool uriFileExists(const std::string& path, void*) {
    std::error_code ec;
    return fs::exists(path, ec);  // by its status: opening a pipe to try it would block
}

std::string uriFileExpand(const std::string& path, void*) { return path; }  // no ~ or $ expansion, as tinygltf's

// Opens the file once and reads it straight into tinygltf's vector, which tinygltf swaps into
// the buffer or hands to the image callback: a buffer's bytes are held once, never copied.
bool uriFileRead(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    UriFiles& files = *static_cast<UriFiles*>(user);
    const uint64_t limit = files.imagePaths.count(path) ? kMaxImageFileBytes : kMaxBufferFileBytes;
    std::string problem;
    try {
        InputFile file(path, UINT64_MAX, "a file");
        problem = uriFileSizeProblem(file.size(), limit, files.heldBytes);
        if (problem.empty()) {
            out->resize(size_t(file.size()));
            file.readAllInto(out->data());
            files.heldBytes += file.size();
        }
    } catch (const InputError& e) {
        problem = uriFileProblem(e.problem());
    }
    if (problem.empty()) return true;
    out->clear();
    out->shrink_to_fit();
    files.problems[path] = problem;
    if (err) *err += problem;
    return false;
}

bool uriFileWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "qsgi writes no file while reading a glTF";
    return false;
}

// Why the file of `uri` was not read: what the reader found, else that it is nowhere tinygltf looks.
std::string uriReadProblem(const UriFiles& files, const std::string& uri) {
    for (const std::string& path : uriFilePaths(files.baseDir, uri)) {
        auto found = files.problems.find(path);
        if (found != files.problems.end()) return found->second;
    }
    return "names no file (looked beside the glTF file)";
}

// tinygltf's warnings about an image file it could not read: the loader says the same in its own
// words, for the images a material uses.
bool isImageFileWarning(const std::string& line) {
    for (const char* start : {"File not found : ", "File read error : ", "File is empty : ",
                              "Failed to load external 'uri' for image[", "Image data is empty for image["})
        if (line.rfind(start, 0) == 0) return true;
    return false;
}

bool isFileUri(const json& item) {
    return item.is_object() && item.contains("uri") && item["uri"].is_string() &&
           item["uri"].get<std::string>().rfind("data:", 0) != 0;
}

std::string firstLine(const std::string& s) {
    std::string out = s.substr(0, s.find('\n'));
    return out.empty() ? s : out;
}

}  // namespace

GltfDocument readGltfDocument(const std::string& path, Warnings& warnings) {
    return parseGltfDocument(path, readBytes(path), fs::absolute(fs::path(path)).parent_path().string(), warnings);
}

GltfDocument parseGltfDocument(const std::string& path, std::string bytes, const std::string& baseDir,
                               Warnings& warnings) {
    refuseBeyondGltfSize(path, bytes.size());
    const bool binary = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    GlbLayout glb;
    const uint32_t declared = binary && bytes.size() >= 20 ? readU32(bytes, 8) : 0;
    if (declared >= 20 && declared < bytes.size()) {
        // Bytes after the length the header declares are no part of the file (glTF 2.0 §4.4.2:
        // the validator lets them pass with a note); they are left unread.
        warnings.add(path + ": GLB header: " + std::to_string(bytes.size() - declared) +
                     " bytes follow the declared end of the file and are ignored");
        bytes.resize(declared);
    }
    if (binary) glb = readGlbLayout(path, bytes);
    const std::string& jsonText = binary ? glb.jsonText : bytes;
    // Before any parser: tinygltf copies extras recursively and would overflow the stack.
    refuseDeepNesting(jsonText, path, binary ? 20 : 0);

    json doc;
    try {
        doc = json::parse(jsonText);
    } catch (const json::parse_error& e) {
        throw InputError(path, "byte " + std::to_string(e.byte + (binary ? 20 : 0)), "not valid JSON");
    } catch (const json::exception&) {
        throw InputError(path, "", "not usable JSON (a number too large for a double?)");
    }
    if (!doc.is_object()) throw InputError(path, "", "the glTF JSON must be an object");
    checkAsset(path, doc);
    json original = doc;
    bool rewritten = refuseNegativeIndices(path, doc);
    rewritten = rewritePlainDataUris(doc, "buffers") || rewritten;
    rewritten = rewritePlainDataUris(doc, "images") || rewritten;
    refuseRemoteUris(path, doc, "buffers");
    refuseRemoteUris(path, doc, "images");

    GltfDocument out;
    out.json = std::move(original);
    out.baseDir = baseDir;
    out.findings = findReferenceProblems(doc);
    // Document-level slips that leave the file readable: warnings, refused under --strict.
    if (jsonText.size() >= 3 && jsonText.compare(0, 3, "\xEF\xBB\xBF") == 0)
        out.findings.push_back({"", binary ? "GLB chunk 0" : "byte 0", "starts with a byte-order mark, which glTF forbids"});
    if (binary && glb.binChunks > 1)
        out.findings.push_back({"", "GLB", "has " + std::to_string(glb.binChunks) + " BIN chunks; glTF allows one (the first is read)"});
    out.absentBuffers = replaceAbsentBuffers(doc, binary);
    if (!out.absentBuffers.empty() || rewritten) {
        std::string rewritten = doc.dump();
        if (binary) {
            while (rewritten.size() % 4) rewritten += ' ';
            std::string container = bytes.substr(0, 12);
            appendU32(container, uint32_t(rewritten.size()));
            appendU32(container, kGlbJsonChunk);
            container += rewritten;
            container += bytes.substr(glb.afterJson);
            const uint32_t total = uint32_t(container.size());
            std::memcpy(container.data() + 8, &total, 4);
            bytes = std::move(container);
        } else {
            bytes = std::move(rewritten);
        }
    }

    UriFiles files;
    files.baseDir = baseDir;
    if (doc.contains("images") && doc["images"].is_array())
        for (const json& image : doc["images"])
            if (isFileUri(image))
                for (const std::string& p : uriFilePaths(baseDir, image["uri"].get<std::string>())) files.imagePaths.insert(p);
    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(keepEncodedImage, nullptr);
    loader.SetFsCallbacks({uriFileExists, uriFileExpand, uriFileRead, uriFileWrite, &files});
    std::string err, warn;
    bool ok = false;
    try {
        ok = binary ? loader.LoadBinaryFromMemory(&out.model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                                  unsigned(bytes.size()), baseDir)
                    : loader.LoadASCIIFromString(&out.model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir);
    } catch (const std::exception& e) {
        throw InputError(path, "", std::string("not a readable glTF file: ") + e.what());
    }
    if (!ok) {
        // A buffer's file that could not be read, named by its place.
        if (doc.contains("buffers") && doc["buffers"].is_array())
            for (size_t i = 0; i < doc["buffers"].size(); ++i) {
                const json& buffer = doc["buffers"][i];
                if (!isFileUri(buffer)) continue;
                const std::string uri = buffer["uri"].get<std::string>();
                const std::vector<std::string> paths = uriFilePaths(baseDir, uri);
                const auto read = std::find_if(paths.begin(), paths.end(), [](const std::string& p) { return uriFileExists(p, nullptr); });
                if (read == paths.end() || files.problems.count(*read))
                    throw InputError(path, "buffers[" + std::to_string(i) + "].uri", "'" + uri.substr(0, 200) + "' " +
                                                                                        uriReadProblem(files, uri));
            }
        throw InputError(path, "", "not a valid glTF file: " + firstLine(err.empty() ? warn : err));
    }
    if (doc.contains("images") && doc["images"].is_array())
        for (size_t i = 0; i < doc["images"].size() && i < out.model.images.size(); ++i) {
            const tinygltf::Image& image = out.model.images[i];
            if (isFileUri(doc["images"][i]) && image.bufferView < 0 && image.image.empty())
                out.unreadableImages[int(i)] = uriReadProblem(files, doc["images"][i]["uri"].get<std::string>());
        }
    for (size_t start = 0; start < warn.size();) {
        size_t end = warn.find('\n', start);
        if (end == std::string::npos) end = warn.size();
        if (end > start && !isImageFileWarning(warn.substr(start, end - start)))
            warnings.add(path + ": " + warn.substr(start, end - start));
        start = end + 1;
    }
    return out;
}

}  // namespace qsgi
