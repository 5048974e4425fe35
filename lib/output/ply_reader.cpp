#include "output/ply_reader.h"

#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "util/error.h"

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
}  // namespace

VertexRadiosityPly readVertexRadiosityPly(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", "cannot be opened for reading");
    std::string line;
    if (!std::getline(in, line) || line != "ply") throw InputError(path, "line 1", "not a PLY file");
    size_t vertexCount = 0, faceCount = 0;
    bool inVertex = false, inFace = false, binaryLittleEndian = false, sawVertex = false;
    std::string faceCountType, faceIndexType;
    struct Property { std::string name, type; size_t offset; };
    std::vector<Property> properties;
    size_t stride = 0;
    int lineNo = 1;
    while (std::getline(in, line)) {
        ++lineNo;
        std::istringstream words(line);
        std::string word;
        words >> word;
        if (word == "end_header") break;
        if (word == "format") {
            std::string format;
            words >> format;
            binaryLittleEndian = format == "binary_little_endian";
        } else if (word == "element") {
            std::string name;
            words >> name;
            inVertex = name == "vertex";
            inFace = name == "face";
            if (inFace) words >> faceCount;
            if (inVertex) {
                if (sawVertex || !properties.empty()) throw InputError(path, "line " + std::to_string(lineNo), "vertex must be the first element");
                words >> vertexCount;
                sawVertex = true;
            }
        } else if (word == "property" && inFace) {
            std::string type, countType, indexType, name;
            words >> type >> countType >> indexType >> name;
            if (type != "list" || name != "vertex_indices" || sizeOfType(countType) == 0 || sizeOfType(indexType) == 0)
                throw InputError(path, "line " + std::to_string(lineNo), "faces must be a single list property vertex_indices");
            faceCountType = countType;
            faceIndexType = indexType;
        } else if (word == "property" && inVertex) {
            std::string type, name;
            words >> type >> name;
            if (type == "list" || sizeOfType(type) == 0)
                throw InputError(path, "line " + std::to_string(lineNo), "unsupported vertex property type '" + type + "'");
            properties.push_back({name, type, stride});
            stride += sizeOfType(type);
        }
    }
    if (!binaryLittleEndian) throw InputError(path, "header", "only binary_little_endian PLY is read");
    if (!sawVertex) throw InputError(path, "header", "has no vertex element");
    auto find = [&](const char* name) -> const Property& {
        for (const auto& p : properties)
            if (p.name == name) return p;
        throw InputError(path, "header", std::string("has no vertex property '") + name + "'");
    };
    const Property* fields[9] = {&find("x"), &find("y"), &find("z"), &find("nx"), &find("ny"), &find("nz"),
                                 &find("radiosity_r"), &find("radiosity_g"), &find("radiosity_b")};
    if (vertexCount > (size_t(1) << 31)) throw InputError(path, "header", "implausible vertex count");
    std::vector<char> data(vertexCount * stride);
    if (!in.read(data.data(), std::streamsize(data.size())))
        throw InputError(path, "vertex data", "ends before " + std::to_string(vertexCount) + " vertices");
    VertexRadiosityPly out;
    out.positions.resize(vertexCount);
    out.normals.resize(vertexCount);
    out.radiosity.resize(vertexCount);
    for (size_t v = 0; v < vertexCount; ++v) {
        const char* row = data.data() + v * stride;
        float f[9];
        for (int i = 0; i < 9; ++i) f[i] = float(readScalar(row + fields[i]->offset, fields[i]->type));
        out.positions[v] = {f[0], f[1], f[2]};
        out.normals[v] = {f[3], f[4], f[5]};
        out.radiosity[v] = {f[6], f[7], f[8]};
        if (!isFinite(out.radiosity[v])) throw InputError(path, "vertex " + std::to_string(v), "radiosity is not finite");
    }
    // Faces (fanned into triangles), for the edge regions of `qsgi compare`.
    if (faceCount > (size_t(1) << 31)) throw InputError(path, "header", "implausible face count");
    std::vector<char> buffer(8);
    for (size_t f = 0; f < faceCount && !faceIndexType.empty(); ++f) {
        const std::string where = "face " + std::to_string(f);
        if (!in.read(buffer.data(), std::streamsize(sizeOfType(faceCountType)))) throw InputError(path, where, "file ends here");
        const double corners = readScalar(buffer.data(), faceCountType);
        if (!(corners >= 3 && corners <= 255)) throw InputError(path, where, "has fewer than 3 corners");
        std::vector<uint32_t> index(static_cast<size_t>(corners));
        for (uint32_t& i : index) {
            if (!in.read(buffer.data(), std::streamsize(sizeOfType(faceIndexType)))) throw InputError(path, where, "file ends here");
            const double value = readScalar(buffer.data(), faceIndexType);
            if (!(value >= 0 && value < double(vertexCount))) throw InputError(path, where, "refers to a vertex that does not exist");
            i = uint32_t(value);
        }
        for (size_t k = 1; k + 1 < index.size(); ++k) out.triangles.push_back(Triangle{{index[0], index[k], index[k + 1]}});
    }
    return out;
}

}  // namespace qsgi
