#include "output/refined_attributes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace qsgi {

using nlohmann::json;

namespace {

// glTF's element type names as tinygltf numbers them.
int elementType(const std::string& type) {
    return type == "SCALAR" ? TINYGLTF_TYPE_SCALAR : type == "VEC2" ? TINYGLTF_TYPE_VEC2 : type == "VEC3" ? TINYGLTF_TYPE_VEC3
         : type == "VEC4" ? TINYGLTF_TYPE_VEC4 : -1;
}

}  // namespace

json refinedPrimitive(json primitive, const json& doc, BinaryBuilder& bin, const AccessorReader& reader,
                      const Scene& scene, const MeshInstance& inst, const std::string& place) {
    const size_t own = inst.vertexCount - inst.refinedFrom.size();
    auto refined = [&](int index, const std::string& usedBy, bool unit, bool tangent, bool bounds) {
        const json& a = doc["accessors"][size_t(index)];
        const std::string type = a.value("type", "");
        const AccessorFormat format{elementType(type), {{a.value("componentType", 0), a.value("normalized", false)}}, {}};
        const AccessorData data = reader.readUnbounded(index, usedBy, format);
        const size_t c = size_t(data.components);
        if (data.count != own) throw InputError(scene.sourcePath, usedBy, "has " + std::to_string(data.count) + " elements, not the primitive's " + std::to_string(own));
        std::vector<float> out(size_t(inst.vertexCount) * c);
        for (size_t i = 0; i < own * c; ++i) out[i] = float(data.values[i]);
        for (size_t j = 0; j < inst.refinedFrom.size(); ++j) {
            const size_t p = inst.refinedFrom[j].first, q = inst.refinedFrom[j].second;
            float* o = &out[(own + j) * c];
            for (size_t k = 0; k < c; ++k) o[k] = float(0.5 * (double(out[p * c + k]) + double(out[q * c + k])));
            if (unit && c >= 3) {
                const double n = std::sqrt(double(o[0]) * o[0] + double(o[1]) * o[1] + double(o[2]) * o[2]);
                for (size_t k = 0; k < 3; ++k) o[k] = n > 0 ? float(o[k] / n) : out[p * c + k];
            }
            if (tangent && c == 4) o[3] = out[p * c + 3];
        }
        json accessor = {{"bufferView", bin.addView(out.data(), out.size() * 4, kArrayBuffer)}, {"componentType", kFloat},
                         {"count", inst.vertexCount}, {"type", type}};
        if (bounds) {
            std::vector<float> lo(c, INFINITY), hi(c, -INFINITY);
            for (size_t i = 0; i < out.size(); ++i) {
                lo[i % c] = std::min(lo[i % c], out[i]);
                hi[i % c] = std::max(hi[i % c], out[i]);
            }
            accessor["min"] = lo;
            accessor["max"] = hi;
        }
        return bin.addAccessor(std::move(accessor));
    };
    json& attributes = primitive["attributes"];
    for (auto& [name, index] : attributes.items()) {
        if (name.rfind("JOINTS_", 0) == 0 || name.rfind("WEIGHTS_", 0) == 0) continue;  // below
        index = refined(index.get<int>(), place + ".attributes." + name, name == "NORMAL", name == "TANGENT", name == "POSITION");
    }
    // The joints and weights the refinement blended (four influences a set).
    const size_t influences = size_t(inst.influences);
    for (size_t set = 0; set * 4 < influences; ++set) {
        std::vector<uint16_t> joints(size_t(inst.vertexCount) * 4);
        std::vector<float> weights(size_t(inst.vertexCount) * 4);
        for (size_t v = 0; v < inst.vertexCount; ++v)
            for (size_t k = 0; k < 4; ++k) {
                joints[v * 4 + k] = inst.skinJoints[v * influences + set * 4 + k];
                weights[v * 4 + k] = inst.skinWeights[v * influences + set * 4 + k];
            }
        attributes["JOINTS_" + std::to_string(set)] = bin.addAccessor(
            {{"bufferView", bin.addView(joints.data(), joints.size() * 2, kArrayBuffer)}, {"componentType", 5123}, {"count", inst.vertexCount}, {"type", "VEC4"}});
        attributes["WEIGHTS_" + std::to_string(set)] = bin.addAccessor(
            {{"bufferView", bin.addView(weights.data(), weights.size() * 4, kArrayBuffer)}, {"componentType", kFloat}, {"count", inst.vertexCount}, {"type", "VEC4"}});
    }
    if (primitive.contains("targets"))
        for (size_t t = 0; t < primitive["targets"].size(); ++t)
            for (auto& [name, index] : primitive["targets"][t].items())
                index = refined(index.get<int>(), place + ".targets[" + std::to_string(t) + "]." + name, false, false, name == "POSITION");
    // The refined triangles, in the file's winding (the scene turned a mirrored instance's).
    std::vector<uint32_t> indices;
    indices.reserve(size_t(inst.triangleCount) * 3);
    for (uint32_t t = 0; t < inst.triangleCount; ++t) {
        Triangle tri = scene.triangles[inst.firstTriangle + t];
        if (inst.mirrored) std::swap(tri.v[1], tri.v[2]);
        for (const uint32_t v : tri.v) indices.push_back(v - inst.firstVertex);
    }
    primitive["indices"] = bin.addAccessor({{"bufferView", bin.addView(indices.data(), indices.size() * 4, kElementArrayBuffer)},
                                            {"componentType", kUnsignedInt}, {"count", indices.size()}, {"type", "SCALAR"}});
    if (primitive.contains("mode")) primitive["mode"] = 4;  // strips and fans come back as triangles
    return primitive;
}

}  // namespace qsgi
