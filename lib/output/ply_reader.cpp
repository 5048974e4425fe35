#include "output/ply_reader.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <istream>
#include <map>
#include <sstream>

#include "util/error.h"
#include "util/input_file.h"

namespace qsgi {

namespace {

size_t sizeOfType(const std::string& t) {
    static const std::map<std::string, size_t> sizes = {
        {"char", 1}, {"uchar", 1}, {"int8", 1}, {"uint8", 1}, {"short", 2}, {"ushort", 2}, {"int16", 2},
        {"uint16", 2}, {"int", 4}, {"uint", 4}, {"int32", 4}, {"uint32", 4}, {"float", 4}, {"float32", 4},
        {"double", 8}, {"float64", 8}};
    auto it = sizes.find(t);
    return it == sizes.end() ? 0 : it->second;
}

double readScalar(const char* p, const std::string& t) {
    auto get = [p](auto v) { std::memcpy(&v, p, sizeof v); return double(v); };
    if (t == "float" || t == "float32") return get(float());
    if (t == "double" || t == "float64") return get(double());
    if (t == "uchar" || t == "uint8") return get(uint8_t());
    if (t == "char" || t == "int8") return get(int8_t());
    if (t == "ushort" || t == "uint16") return get(uint16_t());
    if (t == "short" || t == "int16") return get(int16_t());
    if (t == "uint" || t == "uint32") return get(uint32_t());
    return get(int32_t());
}

struct PlyProperty {
    std::string name, type;         // type: the scalar's, or the list's items'
    std::string countType;          // a list's count type; "" for a scalar
    size_t offset = 0;              // a scalar's byte offset in a vertex row
};

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    int line = 0;  // of its `element` line
    std::vector<PlyProperty> properties;
    // The fewest bytes one element can take: a scalar's size (binary) or two characters, a digit
    // and a separator (ASCII); a list's count and, for faces, three corners (fewer are refused).
    uint64_t minimumBytes(bool ascii) const {
        uint64_t bytes = 0;
        for (const PlyProperty& p : properties) {
            const uint64_t item = ascii ? 2 : sizeOfType(p.type);
            if (p.countType.empty()) bytes += item;
            else bytes += (ascii ? 2 : sizeOfType(p.countType)) + (name == "face" ? 3 * item : 0);
        }
        return bytes;
    }
};

// A count in an `element` line: a non-negative decimal integer.
bool parseCount(const std::string& word, uint64_t& count) {
    if (word.empty() || word.size() > 19 || word.find_first_not_of("0123456789") != std::string::npos) return false;
    count = std::stoull(word);
    return true;
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    return text;
}

const char* plural(const std::string& element) {
    return element == "vertex" ? "vertices" : element == "face" ? "faces" : element == "point" ? "points" : "elements";
}

// The header of a binary PLY whose first element is `first`: every element with its count and
// properties, checked against the file's size before any data is read. The file's stream is left
// at the data.
std::vector<PlyElement> readHeader(InputFile& file, const std::string& first) {
    const std::string& path = file.path();
    const uint64_t fileSize = file.size();
    std::istream& in = file.stream();
    in.clear();
    in.seekg(0);  // after plyFirstElement's look at the header

    std::string line;
    if (!std::getline(in, line) || line != "ply") throw InputError(path, "line 1", "not a PLY file");
    std::string format;
    std::vector<PlyElement> elements;
    bool ended = false;
    for (int lineNo = 2; std::getline(in, line); ++lineNo) {
        const std::string at = "line " + std::to_string(lineNo);
        std::istringstream words(line);
        std::string word;
        words >> word;
        if (word == "end_header") {
            ended = true;
            break;
        }
        if (word == "format") {
            words >> format;
        } else if (word == "element") {
            PlyElement e;
            std::string count;
            words >> e.name >> count;
            if (!parseCount(count, e.count))
                throw InputError(path, at, "element '" + e.name + "' needs a count, a non-negative integer ('" +
                                               count.substr(0, 40) + "' is not one)");
            e.line = lineNo;
            if (e.name == first && !elements.empty()) throw InputError(path, at, first + " must be the first element");
            elements.push_back(e);
        } else if (word == "property") {
            if (elements.empty()) throw InputError(path, at, "a property before any element");
            PlyElement& e = elements.back();
            PlyProperty p;
            std::string type;
            words >> type;
            if (type == "list") {
                words >> p.countType >> p.type >> p.name;
                if (sizeOfType(p.countType) == 0 || sizeOfType(p.type) == 0)
                    throw InputError(path, at, "unsupported list property types '" + p.countType + "' and '" + p.type + "'");
            } else {
                words >> p.name;
                p.type = type;
                if (sizeOfType(type) == 0) throw InputError(path, at, "unsupported property type '" + type + "'");
            }
            if (e.name == first && !p.countType.empty())
                throw InputError(path, at, "unsupported " + first + " property type 'list'");
            if (e.name == "face" && (p.countType.empty() || p.name != "vertex_indices" || !e.properties.empty()))
                throw InputError(path, at, "faces must be a single list property vertex_indices");
            e.properties.push_back(p);
        }
    }
    if (!ended) throw InputError(path, "header", "has no end_header line");

    // Every element needs some bytes: counts the file cannot hold are refused before anything is
    // allocated for them (a header may claim 10^8 vertices in a file of 3 KB).
    const bool ascii = format == "ascii";
    const uint64_t headerEnd = uint64_t(in.tellg());
    const uint64_t remaining = fileSize > headerEnd ? fileSize - headerEnd : 0;
    uint64_t needed = 0;
    for (const PlyElement& e : elements) {
        const uint64_t each = e.minimumBytes(ascii);
        if (each == 0) continue;
        if (e.count > (remaining - needed) / each)
            throw InputError(path, "header, element " + e.name + " (line " + std::to_string(e.line) + ")",
                             "declares " + std::to_string(e.count) + " " + plural(e.name) + " of at least " +
                                 std::to_string(each) + " bytes each, but only " + std::to_string(remaining - needed) +
                                 " bytes of the file's " + std::to_string(fileSize) + " are left for them");
        needed += e.count * each;
    }
    if (format != "binary_little_endian") throw InputError(path, "header", "only binary_little_endian PLY is read");
    if (elements.empty() || elements[0].name != first) throw InputError(path, "header", "has no " + first + " element");
    return elements;
}

// The first element's rows, every property finite: its properties (with their offsets), the
// row size and the bytes. `in` is left after them.
struct PlyRows {
    std::vector<PlyProperty> properties;
    size_t stride = 0;
    std::vector<char> data;
    const PlyProperty* find(const std::string& name) const {
        for (const auto& p : properties)
            if (p.name == name) return &p;
        return nullptr;
    }
    double value(size_t row, const PlyProperty& p) const { return readScalar(data.data() + row * stride + p.offset, p.type); }
};

// The first element's properties with their offsets in a row, and the row's size.
PlyRows layoutOf(const PlyElement& element) {
    PlyRows rows;
    rows.properties = element.properties;
    for (PlyProperty& p : rows.properties) {
        p.offset = rows.stride;
        rows.stride += sizeOfType(p.type);
    }
    return rows;
}

// Reads the rows of `rows`' layout (layoutOf), every property finite.
void readFirstElementRows(const std::string& path, std::istream& in, const PlyElement& element, PlyRows& rows) {
    const size_t count = size_t(element.count);
    if (count > (size_t(1) << 31)) throw InputError(path, "header", "implausible " + element.name + " count");
    rows.data.resize(count * rows.stride);
    if (!in.read(rows.data.data(), std::streamsize(rows.data.size())))
        throw InputError(path, element.name + " data", "ends before " + std::to_string(count) + " " + plural(element.name));
    for (size_t r = 0; r < count; ++r)
        for (const PlyProperty& p : rows.properties) {
            const double value = rows.value(r, p);
            if (!std::isfinite(value))
                throw InputError(path, element.name + " " + std::to_string(r),
                                 "property '" + p.name + "' is " + number(value) + ", not a finite number");
        }
}

}  // namespace

VertexRadiosityPly readVertexRadiosityPly(const std::string& path) {
    InputFile file(path, UINT64_MAX, "a PLY file");
    return readVertexRadiosityPly(file);
}

VertexRadiosityPly readVertexRadiosityPly(InputFile& file) {
    const std::string& path = file.path();
    const std::vector<PlyElement> elements = readHeader(file, "vertex");
    std::istream& in = file.stream();
    // Vertices: every property of every vertex finite, the nine qsgi reads within float's range
    // (the properties are looked for before any row is read).
    PlyRows rows = layoutOf(elements[0]);
    auto find = [&](const char* name) -> const PlyProperty& {
        if (const PlyProperty* p = rows.find(name)) return *p;
        throw InputError(path, "header", std::string("has no vertex property '") + name + "'");
    };
    const PlyProperty* fields[9] = {&find("x"), &find("y"), &find("z"), &find("nx"), &find("ny"), &find("nz"),
                                    &find("radiosity_r"), &find("radiosity_g"), &find("radiosity_b")};
    // Irradiance, which qsgi writes since issue 35 (the asset's _IRRADIANCE is read from it): all
    // three or none.
    const PlyProperty* irradiance[3] = {rows.find("irradiance_r"), rows.find("irradiance_g"), rows.find("irradiance_b")};
    const bool hasIrradiance = irradiance[0] && irradiance[1] && irradiance[2];
    // The back sides of doubleSided surfaces (since issue 57): all six or none.
    const PlyProperty* back[6] = {rows.find("back_radiosity_r"),  rows.find("back_radiosity_g"),  rows.find("back_radiosity_b"),
                                  rows.find("back_irradiance_r"), rows.find("back_irradiance_g"), rows.find("back_irradiance_b")};
    bool hasBack = true;
    for (const PlyProperty* p : back) hasBack = hasBack && p;
    const PlyProperty* referenced = rows.find("referenced");
    readFirstElementRows(path, in, elements[0], rows);
    const size_t vertexCount = size_t(elements[0].count);
    VertexRadiosityPly out;
    out.positions.resize(vertexCount);
    out.normals.resize(vertexCount);
    out.radiosity.resize(vertexCount);
    if (hasIrradiance) out.irradiance.resize(vertexCount);
    if (referenced) out.referenced.resize(vertexCount);
    if (hasBack) out.backRadiosity.resize(vertexCount), out.backIrradiance.resize(vertexCount);
    auto asFloat = [&](size_t v, const PlyProperty& p) {
        const double value = rows.value(v, p);
        const float f = float(value);
        if (!std::isfinite(f))
            throw InputError(path, "vertex " + std::to_string(v), "property '" + p.name + "' is " + number(value) + ", beyond the range of float");
        return f;
    };
    for (size_t v = 0; v < vertexCount; ++v) {
        float f[9];
        for (int i = 0; i < 9; ++i) f[i] = asFloat(v, *fields[i]);
        out.positions[v] = {f[0], f[1], f[2]};
        out.normals[v] = {f[3], f[4], f[5]};
        out.radiosity[v] = {f[6], f[7], f[8]};
        if (referenced) out.referenced[v] = rows.value(v, *referenced) != 0;
        if (hasIrradiance)
            for (int c = 0; c < 3; ++c) out.irradiance[v][c] = asFloat(v, *irradiance[c]);
        if (hasBack)
            for (int c = 0; c < 3; ++c) {
                out.backRadiosity[v][c] = asFloat(v, *back[c]);
                out.backIrradiance[v][c] = asFloat(v, *back[3 + c]);
            }
    }

    // Faces (fanned into triangles), for the edge regions of `qsgi compare`. Elements between the
    // vertices and the faces are skipped.
    char buffer[8];
    for (size_t k = 1; k < elements.size(); ++k) {
        const PlyElement& e = elements[k];
        if (e.name == "face" && !e.properties.empty()) {
            const PlyProperty& list = e.properties[0];
            for (uint64_t f = 0; f < e.count; ++f) {
                const std::string where = "face " + std::to_string(f);
                if (!in.read(buffer, std::streamsize(sizeOfType(list.countType)))) throw InputError(path, where, "file ends here");
                const double corners = readScalar(buffer, list.countType);
                if (!(corners >= 3 && corners <= 255)) throw InputError(path, where, "has fewer than 3 corners");
                std::vector<uint32_t> index(static_cast<size_t>(corners));
                for (uint32_t& i : index) {
                    if (!in.read(buffer, std::streamsize(sizeOfType(list.type)))) throw InputError(path, where, "file ends here");
                    const double value = readScalar(buffer, list.type);
                    if (!(value >= 0 && value < double(vertexCount)))
                        throw InputError(path, where, "refers to a vertex that does not exist");
                    i = uint32_t(value);
                }
                for (size_t c = 1; c + 1 < index.size(); ++c) out.triangles.push_back(Triangle{{index[0], index[c], index[c + 1]}});
            }
            break;
        }
        bool lists = false;
        size_t scalarBytes = 0;
        for (const PlyProperty& p : e.properties) {
            lists = lists || !p.countType.empty();
            scalarBytes += sizeOfType(p.type);
        }
        if (!lists) {  // fixed-size elements in one step (the header check bounds the product)
            in.seekg(std::streamoff(e.count * scalarBytes), std::ios::cur);
            continue;
        }
        for (uint64_t i = 0; i < e.count; ++i)
            for (const PlyProperty& p : e.properties) {
                uint64_t items = 1;
                if (!p.countType.empty()) {
                    if (!in.read(buffer, std::streamsize(sizeOfType(p.countType))))
                        throw InputError(path, e.name + " " + std::to_string(i), "file ends here");
                    const double n = readScalar(buffer, p.countType);
                    if (!(n >= 0)) throw InputError(path, e.name + " " + std::to_string(i), "a list has a negative length");
                    items = uint64_t(n);
                }
                in.seekg(std::streamoff(items * sizeOfType(p.type)), std::ios::cur);
                if (!in) throw InputError(path, e.name + " " + std::to_string(i), "file ends here");
            }
    }
    return out;
}

SurfaceReferencePly readSurfaceReferencePly(const std::string& path) {
    InputFile file(path, UINT64_MAX, "a PLY file");
    return readSurfaceReferencePly(file);
}

SurfaceReferencePly readSurfaceReferencePly(InputFile& file) {
    const std::string& path = file.path();
    const std::vector<PlyElement> elements = readHeader(file, "point");
    std::istream& in = file.stream();
    if (elements[0].count == 0) throw InputError(path, "header", "has no points: nothing to score");
    PlyRows rows = layoutOf(elements[0]);
    auto find = [&](const std::string& name) -> const PlyProperty& {
        if (const PlyProperty* p = rows.find(name)) return *p;
        throw InputError(path, "header", "has no point property '" + name + "'");
    };
    const PlyProperty& triangle = find("triangle");
    const PlyProperty &b1 = find("b1"), &b2 = find("b2"), &hidden = find("hidden");
    const PlyProperty* position[3] = {&find("x"), &find("y"), &find("z")};
    const PlyProperty* normal[3] = {&find("nx"), &find("ny"), &find("nz")};
    const PlyProperty* irradiance[3] = {&find("irradiance_r"), &find("irradiance_g"), &find("irradiance_b")};
    const PlyProperty* standardError[3] = {&find("stderr_r"), &find("stderr_g"), &find("stderr_b")};
    readFirstElementRows(path, in, elements[0], rows);
    SurfaceReferencePly out;
    out.points.resize(size_t(elements[0].count));
    for (size_t i = 0; i < out.points.size(); ++i) {
        SurfacePoint& p = out.points[i];
        const std::string where = "point " + std::to_string(i);
        const double t = rows.value(i, triangle);
        if (!(t >= 0 && t < 4294967295.0 && t == std::floor(t))) throw InputError(path, where, "its triangle is not a face index");
        p.triangle = uint32_t(t);
        p.b1 = float(rows.value(i, b1));
        p.b2 = float(rows.value(i, b2));
        if (!(p.b1 >= 0 && p.b2 >= 0 && double(p.b1) + double(p.b2) <= 1 + 1e-6))
            throw InputError(path, where, "its barycentrics b1, b2 do not name a point of a triangle");
        for (int c = 0; c < 3; ++c) {
            p.position[c] = float(rows.value(i, *position[c]));
            p.normal[c] = float(rows.value(i, *normal[c]));
            p.irradiance[c] = float(rows.value(i, *irradiance[c]));
            p.standardError[c] = float(rows.value(i, *standardError[c]));
            if (!std::isfinite(p.position[c]) || !std::isfinite(p.normal[c]) || !std::isfinite(p.irradiance[c]) || !std::isfinite(p.standardError[c]) ||
                !(p.standardError[c] >= 0))
                throw InputError(path, where, "its position, irradiance or standard error is beyond float's range, or the error negative");
        }
        p.hidden = rows.value(i, hidden) != 0;
    }
    return out;
}

std::string plyFirstElement(InputFile& file) {
    std::istream& in = file.stream();
    in.clear();
    in.seekg(0);
    std::string line;
    if (!std::getline(in, line) || line != "ply") return "";
    for (int lines = 0; lines < 1000 && std::getline(in, line); ++lines) {
        std::istringstream words(line);
        std::string word, name;
        words >> word;
        if (word == "end_header") break;
        if (word == "element" && (words >> name)) return name;
    }
    return "";
}

}  // namespace qsgi
