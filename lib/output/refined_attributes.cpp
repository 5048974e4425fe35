#include "output/refined_attributes.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "scene/mesh_refinement.h"

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
    // Each added vertex by the refinement's one rule (lib/scene/mesh_refinement.h), which made the
    // scene's own positions and normals: the asset's NORMAL is the normal the bake used.
    auto refined = [&](int index, const std::string& usedBy, RefinedRule rule, bool bounds) {
        const json& a = doc["accessors"][size_t(index)];
        const std::string type = a.value("type", "");
        const AccessorFormat format{elementType(type), {{a.value("componentType", 0), a.value("normalized", false)}}, {}};
        const AccessorData data = reader.readUnbounded(index, usedBy, format);
        const size_t c = size_t(data.components);
        if (data.count != own) throw InputError(scene.sourcePath, usedBy, "has " + std::to_string(data.count) + " elements, not the primitive's " + std::to_string(own));
        if ((rule == RefinedRule::UnitNormal && c != 3) || (rule == RefinedRule::Tangent && c != 4)) rule = RefinedRule::Mean;
        std::vector<float> out(own * c);
        for (size_t i = 0; i < own * c; ++i) out[i] = float(data.values[i]);
        appendRefinedValues(out, c, inst.refinedFrom, rule);
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
        const RefinedRule rule = name == "NORMAL" ? RefinedRule::UnitNormal : name == "TANGENT" ? RefinedRule::Tangent : RefinedRule::Mean;
        index = refined(index.get<int>(), place + ".attributes." + name, rule, name == "POSITION");
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
                index = refined(index.get<int>(), place + ".targets[" + std::to_string(t) + "]." + name, RefinedRule::Mean, name == "POSITION");
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
