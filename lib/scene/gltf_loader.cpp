#include "scene/gltf_loader.h"

#include <tiny_gltf.h>

#include <algorithm>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

#include "scene/gltf_document.h"
#include "util/memory.h"

namespace qsgi {
namespace {

namespace fs = std::filesystem;

// Extensions whose meaning qsgi implements, or which cannot change the radiosity it computes.
const std::set<std::string> kSupportedExtensions = {
    "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_mesh_quantization",
    "KHR_texture_transform"};

std::string at(const std::string& what, int index) { return what + "[" + std::to_string(index) + "]"; }

// Accessor Formats
// What the glTF 2.0 specification (§3.7.2.1, and KHR_mesh_quantization when the file requires it)
// allows for the accessors qsgi reads: their element type, component types and normalisation.
struct AccessorFormat {
    int type;  // TINYGLTF_TYPE_*
    std::vector<std::pair<int, bool>> allowed;           // (componentType, normalized)
    std::vector<std::pair<int, bool>> allowedQuantized;  // more, with KHR_mesh_quantization
};

const AccessorFormat kPositionFormat{
    TINYGLTF_TYPE_VEC3,
    {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}},
    {{TINYGLTF_COMPONENT_TYPE_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_BYTE, true},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},
     {TINYGLTF_COMPONENT_TYPE_SHORT, false}, {TINYGLTF_COMPONENT_TYPE_SHORT, true},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}}};
const AccessorFormat kNormalFormat{
    TINYGLTF_TYPE_VEC3,
    {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}},
    {{TINYGLTF_COMPONENT_TYPE_BYTE, true}, {TINYGLTF_COMPONENT_TYPE_SHORT, true}}};
const AccessorFormat kIndexFormat{
    TINYGLTF_TYPE_SCALAR,
    {{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false}},
    {}};

std::string componentTypeName(int type) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        default: return "componentType " + std::to_string(type);
    }
}

// Accessor Decoding
// An accessor's elements as doubles, `components` per element, normalised integers mapped to
// [0,1] or [-1,1] as the glTF spec says. Every offset is bounds-checked against its buffer, and
// sizes against the machine's memory, before anything is allocated.
struct AccessorData {
    size_t count = 0;
    int components = 0;
    std::vector<double> values;
    double operator()(size_t element, int component) const { return values[element * components + component]; }
};

class AccessorReader {
public:
    AccessorReader(const GltfDocument& document, const std::string& file)
        : model_(document.model), absentBuffers_(document.absentBuffers), file_(file) {
        for (const auto& ext : model_.extensionsRequired) quantized_ = quantized_ || ext == "KHR_mesh_quantization";
    }

    AccessorData read(int accessorIndex, const std::string& usedBy, const AccessorFormat& format) const {
        const std::string place = usedBy + " -> " + at("accessors", accessorIndex);
        if (accessorIndex < 0 || accessorIndex >= int(model_.accessors.size()))
            throw InputError(file_, usedBy, "refers to accessor " + std::to_string(accessorIndex) +
                                                ", which does not exist");
        const tinygltf::Accessor& acc = model_.accessors[accessorIndex];
        checkFormat(acc, format, place);
        AccessorData out;
        out.count = acc.count;
        out.components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        refuseBeyondMemory(saturatingMultiply(acc.count, uint64_t(out.components) * sizeof(double)), file_, place,
                           "its " + std::to_string(acc.count) + " elements");
        if (acc.bufferView >= 0)
            checkRange(acc.bufferView, acc.byteOffset, acc.count, acc.componentType, out.components, place);
        out.values.assign(acc.count * size_t(out.components), 0.0);
        // Without a bufferView the elements are zeros, typically overridden by sparse values.
        if (acc.bufferView >= 0)
            decode(acc.bufferView, acc.byteOffset, acc.count, acc.componentType, acc.normalized, out.components,
                   out.values.data(), nullptr);
        if (acc.sparse.isSparse) applySparse(acc, out, place);
        for (double v : out.values)
            if (!std::isfinite(v)) throw InputError(file_, place, "holds a non-finite number (NaN or Inf)");
        return out;
    }

private:
    void checkFormat(const tinygltf::Accessor& acc, const AccessorFormat& format, const std::string& place) const {
        const int components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (components <= 0 || tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType)) <= 0)
            throw InputError(file_, place, "unknown accessor type or componentType");
        if (acc.type != format.type)
            throw InputError(file_, place, std::string("must be of type ") +
                                               (format.type == TINYGLTF_TYPE_VEC3 ? "VEC3" : "SCALAR"));
        const std::pair<int, bool> used{acc.componentType, acc.normalized};
        auto allows = [&](const std::vector<std::pair<int, bool>>& list) {
            return std::find(list.begin(), list.end(), used) != list.end();
        };
        if (allows(format.allowed) || (quantized_ && allows(format.allowedQuantized))) return;
        const std::string what = (acc.normalized ? "normalized " : "") + componentTypeName(acc.componentType);
        if (allows(format.allowedQuantized))
            throw InputError(file_, place, what + " components need the KHR_mesh_quantization extension, which the "
                                                  "file does not list in extensionsRequired");
        throw InputError(file_, place, what + " components are not allowed here by the glTF 2.0 specification");
    }

    // Checks that `count` elements from a buffer view lie inside the view and its buffer, with
    // the alignment and stride the specification requires.
    void checkRange(int viewIndex, size_t byteOffset, size_t count, int componentType, int components,
                    const std::string& place) const {
        if (viewIndex < 0 || viewIndex >= int(model_.bufferViews.size()))
            throw InputError(file_, place, "refers to bufferView " + std::to_string(viewIndex) + ", which does not exist");
        const std::string viewPlace = at("bufferViews", viewIndex);
        const tinygltf::BufferView& view = model_.bufferViews[viewIndex];
        if (view.buffer < 0 || view.buffer >= int(model_.buffers.size()))
            throw InputError(file_, viewPlace, "refers to a buffer that does not exist");
        if (absentBuffers_.count(view.buffer))
            throw InputError(file_, viewPlace, "reads buffer " + std::to_string(view.buffer) +
                                                   ", which has no uri and so no data");
        const tinygltf::Buffer& buffer = model_.buffers[view.buffer];
        if (uint64_t(view.byteOffset) + uint64_t(view.byteLength) > buffer.data.size())
            throw InputError(file_, viewPlace,
                             "reaches byte " + std::to_string(uint64_t(view.byteOffset) + view.byteLength) + " of buffer " +
                                 std::to_string(view.buffer) + ", which holds only " + std::to_string(buffer.data.size()));
        const uint64_t componentSize = uint64_t(tinygltf::GetComponentSizeInBytes(uint32_t(componentType)));
        const uint64_t elementSize = componentSize * uint64_t(components);
        if (view.byteStride != 0 && (view.byteStride < 4 || view.byteStride > 252 || view.byteStride % 4 != 0))
            throw InputError(file_, viewPlace + ".byteStride",
                             std::to_string(view.byteStride) + " is not a multiple of 4 in 4..252");
        if (view.byteStride != 0 && view.byteStride < elementSize)
            throw InputError(file_, viewPlace + ".byteStride", std::to_string(view.byteStride) + " is smaller than the " +
                                                                   std::to_string(elementSize) + "-byte elements of " + place);
        if (byteOffset % componentSize != 0 || (view.byteOffset + byteOffset) % componentSize != 0)
            throw InputError(file_, place, "byteOffset is not a multiple of its " + std::to_string(componentSize) +
                                               "-byte component size");
        const uint64_t stride = view.byteStride ? view.byteStride : elementSize;
        if (count > 0 && uint64_t(byteOffset) + saturatingMultiply(stride, count - 1) + elementSize > view.byteLength)
            throw InputError(file_, place, "reads past the end of bufferView " + std::to_string(viewIndex));
    }

    // Decodes `count` elements (checked by checkRange) into `doubles` or, for sparse indices,
    // into `indices`.
    void decode(int viewIndex, size_t byteOffset, size_t count, int componentType, bool normalized,
                int components, double* doubles, std::vector<size_t>* indices) const {
        const tinygltf::BufferView& view = model_.bufferViews[viewIndex];
        const tinygltf::Buffer& buffer = model_.buffers[view.buffer];
        const size_t componentSize = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(componentType)));
        const size_t elementSize = componentSize * size_t(components);
        const size_t stride = view.byteStride ? view.byteStride : elementSize;
        const unsigned char* base = buffer.data.data() + view.byteOffset + byteOffset;
        for (size_t e = 0; e < count; ++e) {
            const unsigned char* element = base + e * stride;
            for (int c = 0; c < components; ++c) {
                const double v = component(element + c * componentSize, componentType, normalized);
                if (indices) (*indices)[e] = size_t(v);
                else doubles[e * components + c] = v;
            }
        }
    }

    static double component(const unsigned char* p, int type, bool normalized) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_BYTE: { int8_t v; std::memcpy(&v, p, 1); return normalized ? std::max(v / 127.0, -1.0) : v; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: { uint8_t v; std::memcpy(&v, p, 1); return normalized ? v / 255.0 : v; }
            case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t v; std::memcpy(&v, p, 2); return normalized ? std::max(v / 32767.0, -1.0) : v; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return normalized ? v / 65535.0 : v; }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t v; std::memcpy(&v, p, 4); return normalized ? v / 4294967295.0 : v; }
            case TINYGLTF_COMPONENT_TYPE_FLOAT: { float v; std::memcpy(&v, p, 4); return v; }
            default: return 0;
        }
    }

    void applySparse(const tinygltf::Accessor& acc, AccessorData& out, const std::string& place) const {
        if (acc.sparse.count < 1 || size_t(acc.sparse.count) > out.count)
            throw InputError(file_, place + ".sparse.count", std::to_string(acc.sparse.count) +
                                                                 " is outside 1..count of the accessor");
        const size_t n = size_t(acc.sparse.count);
        const int indexType = acc.sparse.indices.componentType;
        if (indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            indexType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            throw InputError(file_, place + ".sparse.indices.componentType", "must be an unsigned integer type");
        checkRange(acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset), n, indexType, 1,
                   place + ".sparse.indices");
        checkRange(acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset), n, acc.componentType,
                   out.components, place + ".sparse.values");
        std::vector<size_t> targets(n);
        decode(acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset), n, indexType, false, 1, nullptr,
               &targets);
        std::vector<double> values(n * size_t(out.components));
        decode(acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset), n, acc.componentType,
               acc.normalized, out.components, values.data(), nullptr);
        for (size_t i = 0; i < n; ++i) {
            if (targets[i] >= out.count)
                throw InputError(file_, place + ".sparse.indices", "index " + std::to_string(targets[i]) +
                                                                       " is beyond the accessor's count");
            if (i > 0 && targets[i] <= targets[i - 1])
                throw InputError(file_, place + ".sparse.indices", "must strictly increase (index " +
                                                                       std::to_string(targets[i]) + " follows " +
                                                                       std::to_string(targets[i - 1]) + ")");
            for (int c = 0; c < out.components; ++c) out.values[targets[i] * out.components + c] = values[i * out.components + c];
        }
    }

    const tinygltf::Model& model_;
    const std::set<int>& absentBuffers_;
    const std::string& file_;
    bool quantized_ = false;
};

// Textures and Materials
double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// Mean linear colour of a decoded image, or nullopt if it was not loaded (e.g. file missing).
std::optional<Vec3f> meanImageColour(const tinygltf::Image& image) {
    const int channels = image.component;
    const int bytesPerChannel = image.bits == 16 ? 2 : 1;
    const size_t pixels = size_t(std::max(image.width, 0)) * size_t(std::max(image.height, 0));
    if (pixels == 0 || channels <= 0 || image.image.size() < pixels * channels * bytesPerChannel) return std::nullopt;
    const double maxValue = bytesPerChannel == 2 ? 65535.0 : 255.0;
    double sum[3] = {0, 0, 0};
    for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
            const int channel = channels >= 3 ? c : 0;
            const size_t offset = (p * channels + channel) * bytesPerChannel;
            uint32_t v = image.image[offset];
            if (bytesPerChannel == 2) v |= uint32_t(image.image[offset + 1]) << 8;
            sum[c] += srgbToLinear(v / maxValue);
        }
    return Vec3f(float(sum[0] / pixels), float(sum[1] / pixels), float(sum[2] / pixels));
}

std::optional<Vec3f> textureMean(const tinygltf::Model& model, int textureIndex) {
    if (textureIndex < 0 || textureIndex >= int(model.textures.size())) return std::nullopt;
    const int source = model.textures[textureIndex].source;
    if (source < 0 || source >= int(model.images.size())) return std::nullopt;
    return meanImageColour(model.images[source]);
}

Vec3f vec3FromFactor(const std::vector<double>& f, Vec3f fallback) {
    return f.size() >= 3 ? Vec3f(float(f[0]), float(f[1]), float(f[2])) : fallback;
}

Material convertMaterial(const tinygltf::Model& model, int index, const std::string& file, Warnings& warnings) {
    const tinygltf::Material& m = model.materials[index];
    const std::string place = at("materials", index);
    Material out;
    out.name = m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    out.albedo = vec3FromFactor(pbr.baseColorFactor, Vec3f(1.0f));
    if (pbr.baseColorTexture.index >= 0) {
        if (auto mean = textureMean(model, pbr.baseColorTexture.index)) out.albedo = out.albedo * *mean;
        else warnings.add(file + ": " + place + ": base colour texture could not be read; using baseColorFactor alone");
    }
    if (!isFinite(out.albedo) || out.albedo.x < 0 || out.albedo.y < 0 || out.albedo.z < 0 || maxComponent(out.albedo) > 1) {
        warnings.add(file + ": " + place + ": albedo outside [0,1] clamped (energy must not grow)");
        out.albedo = min(max(out.albedo, Vec3f(0.0f)), Vec3f(1.0f));
        if (!isFinite(out.albedo)) out.albedo = Vec3f(0.0f);
    }
    if (pbr.metallicRoughnessTexture.index >= 0 || m.normalTexture.index >= 0 || m.occlusionTexture.index >= 0)
        warnings.add(file + ": metallic/roughness, normal and occlusion maps are ignored (surfaces are Lambertian)");

    Vec3f emissive = vec3FromFactor(m.emissiveFactor, Vec3f(0.0f));
    if (m.emissiveTexture.index >= 0 && maxComponent(emissive) > 0) {
        if (auto mean = textureMean(model, m.emissiveTexture.index)) emissive = emissive * *mean;
    }
    auto strength = m.extensions.find("KHR_materials_emissive_strength");
    if (strength != m.extensions.end() && strength->second.Has("emissiveStrength")) {
        const auto& v = strength->second.Get("emissiveStrength");
        if (!v.IsNumber() || !(v.GetNumberAsDouble() >= 0) || !std::isfinite(v.GetNumberAsDouble()))
            throw InputError(file, place + ".extensions.KHR_materials_emissive_strength.emissiveStrength",
                             "must be a finite non-negative number");
        emissive = emissive * float(v.GetNumberAsDouble());
    }
    if (!isFinite(emissive) || emissive.x < 0 || emissive.y < 0 || emissive.z < 0)
        throw InputError(file, place + ".emissiveFactor", "must be finite and non-negative");
    out.emission = emissive;
    return out;
}

// Node Hierarchy
Transform nodeLocalTransform(const tinygltf::Node& n, const std::string& file, int index) {
    const std::string place = at("nodes", index);
    Transform t;
    if (n.matrix.size() == 16) {
        t = Transform::fromColumnMajor(n.matrix.data());
    } else {
        Vec3d tr(0.0), sc(1.0);
        std::array<double, 4> rot{0, 0, 0, 1};
        if (n.translation.size() == 3) tr = {n.translation[0], n.translation[1], n.translation[2]};
        if (n.scale.size() == 3) sc = {n.scale[0], n.scale[1], n.scale[2]};
        if (n.rotation.size() == 4) rot = {n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]};
        t = Transform::fromTRS(tr, rot, sc);
    }
    if (!t.isFinite()) throw InputError(file, place, "transform holds a non-finite number");
    return t;
}

std::vector<SceneNode> buildHierarchy(const tinygltf::Model& model, const std::string& file) {
    std::vector<SceneNode> nodes(model.nodes.size());
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        nodes[i].name = model.nodes[i].name;
        nodes[i].local = nodeLocalTransform(model.nodes[i], file, int(i));
        for (int c : model.nodes[i].children) {
            if (c < 0 || c >= int(nodes.size()))
                throw InputError(file, at("nodes", int(i)) + ".children", "refers to node " + std::to_string(c) + ", which does not exist");
            if (c == int(i)) throw InputError(file, at("nodes", int(i)), "is its own child (the hierarchy has a cycle)");
            if (std::count(nodes[i].children.begin(), nodes[i].children.end(), c))
                throw InputError(file, at("nodes", int(i)) + ".children", "lists node " + std::to_string(c) + " twice");
            if (nodes[c].parent >= 0 && nodes[c].parent != int(i))
                throw InputError(file, at("nodes", c), "has two parents (nodes " + std::to_string(nodes[c].parent) +
                                                           " and " + std::to_string(i) + "); glTF nodes form a tree");
            nodes[c].parent = int(i);
            nodes[i].children.push_back(c);
        }
    }
    // A cycle without a root: following parents from any node must end.
    for (size_t i = 0; i < nodes.size(); ++i) {
        int p = nodes[i].parent;
        size_t steps = 0;
        while (p >= 0) {
            if (++steps > nodes.size())
                throw InputError(file, at("nodes", int(i)), "is its own descendant (the hierarchy has a cycle)");
            p = nodes[p].parent;
        }
    }
    return nodes;
}

// Mesh Flattening
std::vector<uint32_t> triangleIndices(int mode, const std::vector<uint32_t>& idx) {
    std::vector<uint32_t> tri;
    const size_t n = idx.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        tri.assign(idx.begin(), idx.begin() + (n / 3) * 3);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
        for (size_t i = 0; i + 2 < n; ++i) {
            // Alternate the winding so every triangle keeps the strip's orientation.
            if (i % 2 == 0) tri.insert(tri.end(), {idx[i], idx[i + 1], idx[i + 2]});
            else tri.insert(tri.end(), {idx[i + 1], idx[i], idx[i + 2]});
        }
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
        for (size_t i = 1; i + 1 < n; ++i) tri.insert(tri.end(), {idx[0], idx[i], idx[i + 1]});
    }
    return tri;
}

class SceneBuilder {
public:
    SceneBuilder(const GltfDocument& document, const std::string& file, Warnings& warnings)
        : model_(document.model), file_(file), warnings_(warnings), reader_(document, file) {}

    Scene build() {
        Scene scene;
        scene.sourcePath = file_;
        scene.nodes = buildHierarchy(model_, file_);
        for (size_t i = 0; i < model_.materials.size(); ++i)
            scene.materials.push_back(convertMaterial(model_, int(i), file_, warnings_));
        defaultMaterial_ = uint32_t(scene.materials.size());
        scene.materials.push_back(Material{"(default)", Vec3f(1.0f), Vec3f(0.0f)});

        if (model_.scenes.empty()) throw InputError(file_, "scenes", "the file has no scene to render");
        const int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
        if (sceneIndex >= int(model_.scenes.size()))
            throw InputError(file_, "scene", "names scene " + std::to_string(sceneIndex) + ", which does not exist");
        const auto& roots = model_.scenes[sceneIndex].nodes;
        if (roots.empty()) throw InputError(file_, at("scenes", sceneIndex), "has no nodes: nothing to render");

        const std::vector<Transform> world = scene.worldTransforms(scene.restLocals());
        std::vector<uint8_t> visited(scene.nodes.size(), 0);
        std::vector<int> stack;
        for (int r : roots) {
            if (r < 0 || r >= int(scene.nodes.size()))
                throw InputError(file_, at("scenes", sceneIndex) + ".nodes", "refers to node " + std::to_string(r) + ", which does not exist");
            if (scene.nodes[r].parent >= 0)
                throw InputError(file_, at("scenes", sceneIndex) + ".nodes", "lists node " + std::to_string(r) + ", which is not a root");
            stack.push_back(r);
        }
        // Depth-first in file order, so vertex numbering is stable across runs.
        std::reverse(stack.begin(), stack.end());
        while (!stack.empty()) {
            const int n = stack.back();
            stack.pop_back();
            if (visited[n]) continue;
            visited[n] = 1;
            visitNode(scene, n, world[n]);
            const auto& children = scene.nodes[n].children;
            for (auto it = children.rbegin(); it != children.rend(); ++it) stack.push_back(*it);
        }
        scene.cameras.resize(model_.cameras.size());
        scene.finalize();
        checkSceneExtent(scene.positions, scene.bounds(), file_, "nodes");
        return scene;
    }

private:
    void visitNode(Scene& scene, int n, const Transform& world) {
        const tinygltf::Node& node = model_.nodes[n];
        if (node.mesh >= 0) {
            if (node.mesh >= int(model_.meshes.size()))
                throw InputError(file_, at("nodes", n) + ".mesh", "refers to mesh " + std::to_string(node.mesh) + ", which does not exist");
            if (node.skin >= 0) warnings_.add(file_ + ": skins are not applied; the base mesh is used");
            const tinygltf::Mesh& mesh = model_.meshes[node.mesh];
            for (size_t p = 0; p < mesh.primitives.size(); ++p)
                addPrimitive(scene, n, mesh.primitives[p], at("meshes", node.mesh) + "." + at("primitives", int(p)));
        }
        if (node.camera >= 0) addCamera(scene, n, world);
        auto light = node.extensions.find("KHR_lights_punctual");
        if (light != node.extensions.end() && light->second.Has("light")) addLight(scene, n, world, light->second.Get("light"));
    }

    void addPrimitive(Scene& scene, int nodeIndex, const tinygltf::Primitive& prim,
                      const std::string& place) {
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            warnings_.add(file_ + ": point and line primitives are skipped");
            return;
        }
        if (!prim.targets.empty()) warnings_.add(file_ + ": morph targets are not applied; the base mesh is used");
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) throw InputError(file_, place, "has no POSITION attribute");
        const AccessorData positions = reader_.read(pos->second, place + ".attributes.POSITION", kPositionFormat);
                const size_t vertexCount = positions.count;

        std::optional<AccessorData> normals;
        auto nrm = prim.attributes.find("NORMAL");
        if (nrm != prim.attributes.end()) {
            normals = reader_.read(nrm->second, place + ".attributes.NORMAL", kNormalFormat);
            if (normals->count != vertexCount)
                throw InputError(file_, place + ".attributes.NORMAL",
                                 "has " + std::to_string(normals->count) + " elements but POSITION has " +
                                     std::to_string(vertexCount) + " (attribute arrays must have equal lengths)");
        }
        for (const auto& [name, accessor] : prim.attributes) {
            if (accessor >= 0 && accessor < int(model_.accessors.size()) && model_.accessors[accessor].count != vertexCount)
                throw InputError(file_, place + ".attributes." + name,
                                 "has " + std::to_string(model_.accessors[accessor].count) + " elements but POSITION has " +
                                     std::to_string(vertexCount) + " (attribute arrays must have equal lengths)");
        }

        std::vector<uint32_t> indices;
        if (prim.indices >= 0) {
            const AccessorData idx = reader_.read(prim.indices, place + ".indices", kIndexFormat);
            indices.resize(idx.count);
            // The largest value of the index type means "primitive restart", which glTF forbids.
            const double restart = double((uint64_t(1) << (8 * tinygltf::GetComponentSizeInBytes(
                                                              uint32_t(model_.accessors[prim.indices].componentType)))) - 1);
            for (size_t i = 0; i < idx.count; ++i) {
                const double v = idx.values[i];
                if (v == restart)
                    throw InputError(file_, place + ".indices", "index " + std::to_string(uint64_t(v)) + " at position " +
                                                                    std::to_string(i) + " is the primitive-restart value, which glTF forbids");
                if (v < 0 || v >= double(vertexCount))
                    throw InputError(file_, place + ".indices", "index " + std::to_string(uint64_t(v)) + " at position " +
                                                                    std::to_string(i) + " is beyond the " +
                                                                    std::to_string(vertexCount) + " vertices");
                indices[i] = uint32_t(v);
            }
        } else {
            indices.resize(vertexCount);
            for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
        }
        std::vector<uint32_t> tri = triangleIndices(prim.mode, indices);
        if (scene.positions.size() + vertexCount > (size_t(1) << 31))
            throw InputError(file_, place, "the scene exceeds 2^31 vertices");

        uint32_t material = defaultMaterial_;
        if (prim.material >= 0) {
            if (prim.material >= int(model_.materials.size()))
                throw InputError(file_, place + ".material", "refers to material " + std::to_string(prim.material) + ", which does not exist");
            material = uint32_t(prim.material);
        }

        std::vector<Vec3f> objectPositions(vertexCount);
        for (size_t i = 0; i < vertexCount; ++i)
            objectPositions[i] = Vec3f(float(positions(i, 0)), float(positions(i, 1)), float(positions(i, 2)));
        std::vector<Vec3f> objectNormals;
        if (normals) {
            objectNormals.resize(vertexCount);
            for (size_t i = 0; i < vertexCount; ++i)
                objectNormals[i] = Vec3f(float((*normals)(i, 0)), float((*normals)(i, 1)), float((*normals)(i, 2)));
        }
        scene.addInstance(nodeIndex, std::move(objectPositions), std::move(objectNormals), tri, material);
    }

    void addCamera(Scene& scene, int n, const Transform& world) {
        const tinygltf::Node& node = model_.nodes[n];
        if (node.camera >= int(model_.cameras.size()))
            throw InputError(file_, at("nodes", n) + ".camera", "refers to a camera that does not exist");
        const tinygltf::Camera& cam = model_.cameras[node.camera];
        scene.cameras.resize(model_.cameras.size());
        if (scene.cameras[node.camera]) return;  // the first node using a camera places it
        if (cam.type != "perspective") {
            warnings_.add(file_ + ": " + at("cameras", node.camera) + ": only perspective cameras are used; skipped");
            return;
        }
        PerspectiveCamera c;
        c.position = Vec3f(world.applyPoint(Vec3d(0.0)));
        c.forward = Vec3f(normalize(world.applyVector(Vec3d(0, 0, -1))));
        c.up = Vec3f(normalize(world.applyVector(Vec3d(0, 1, 0))));
        c.yfov = float(cam.perspective.yfov);
        c.aspect = float(cam.perspective.aspectRatio);
        c.znear = float(cam.perspective.znear);
        if (!(c.yfov > 0 && c.yfov < 3.14159f) || !isFinite(c.position) || !isFinite(c.forward))
            throw InputError(file_, at("cameras", node.camera), "yfov must lie in (0, pi) and the camera node's transform must be finite");
        scene.cameras[node.camera] = c;
        if (!scene.camera) scene.camera = c;
    }

    void addLight(Scene& scene, int n, const Transform& world, const tinygltf::Value& ref) {
        const std::string place = at("nodes", n) + ".extensions.KHR_lights_punctual.light";
        if (!ref.IsNumber()) throw InputError(file_, place, "must be a light index");
        const int index = ref.GetNumberAsInt();
        if (index < 0 || index >= int(model_.lights.size()))
            throw InputError(file_, place, "refers to light " + std::to_string(index) + ", which does not exist");
        const tinygltf::Light& l = model_.lights[index];
        PunctualLight out;
        out.name = l.name.empty() ? "light " + std::to_string(index) : l.name;
        out.node = n;
        const Vec3f colour = vec3FromFactor(l.color, Vec3f(1.0f));
        out.intensity = colour * float(l.intensity);
        out.position = Vec3f(world.applyPoint(Vec3d(0.0)));  // world space; Scene::finalize re-centres it
        out.direction = Vec3f(normalize(world.applyVector(Vec3d(0, 0, -1))));
        if (l.type == "point") out.type = LightType::Point;
        else if (l.type == "spot") {
            out.type = LightType::Spot;
            const double outer = l.spot.outerConeAngle;
            if (!(outer > 0 && outer <= M_PI / 2 + 1e-9))
                throw InputError(file_, at("KHR_lights_punctual.lights", index) + ".spot.outerConeAngle", "must lie in (0, pi/2]");
            out.cosOuterCone = float(std::cos(outer));
        } else if (l.type == "directional") out.type = LightType::Directional;
        else throw InputError(file_, at("KHR_lights_punctual.lights", index) + ".type", "unknown light type '" + l.type + "'");
        if (!isFinite(out.intensity) || out.intensity.x < 0 || out.intensity.y < 0 || out.intensity.z < 0 ||
            !isFinite(out.position) || dot(out.direction, out.direction) == 0)
            throw InputError(file_, at("KHR_lights_punctual.lights", index), "colour and intensity must be finite and non-negative");
        scene.lights.push_back(out);
    }

    const tinygltf::Model& model_;
    const std::string& file_;
    Warnings& warnings_;
    AccessorReader reader_;
    uint32_t defaultMaterial_ = 0;
};

}  // namespace

namespace {

Scene buildScene(const GltfDocument& document, const std::string& path, Warnings& warnings) {
    const tinygltf::Model& model = document.model;
    for (const auto& ext : model.extensionsRequired)
        if (!kSupportedExtensions.count(ext))
            throw InputError(path, "extensionsRequired", "requires extension " + ext + ", which qsgi does not implement");
    for (const auto& ext : model.extensionsUsed)
        if (!kSupportedExtensions.count(ext)) warnings.add(path + ": extension " + ext + " is ignored");

    return SceneBuilder(document, path, warnings).build();
}

}  // namespace

Scene loadGltfScene(const std::string& path, Warnings& warnings) {
    return buildScene(readGltfDocument(path, warnings), path, warnings);
}

Scene loadGltfSceneFromMemory(const std::string& path, std::string bytes, const std::string& baseDir,
                              Warnings& warnings) {
    return buildScene(parseGltfDocument(path, std::move(bytes), baseDir, warnings), path, warnings);
}

}  // namespace qsgi
