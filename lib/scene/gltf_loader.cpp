#include "scene/gltf_loader.h"

#include <tiny_gltf.h>

#include <algorithm>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "scene/gltf_accessor.h"
#include "scene/gltf_animation.h"
#include "scene/gltf_document.h"
#include "scene/texture_colour.h"
#include "util/memory.h"

namespace qsgi {
namespace {

namespace fs = std::filesystem;

// Extensions whose meaning qsgi implements, or which cannot change the radiosity it computes.
const std::set<std::string> kSupportedExtensions = {
    "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_mesh_quantization",
    "KHR_texture_transform"};

// What the glTF 2.0 specification (§3.7.2.1, and KHR_mesh_quantization when the file requires it)
// allows for the mesh accessors qsgi reads.
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
const AccessorFormat kJointsFormat{
    TINYGLTF_TYPE_VEC4,
    {{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false}},
    {}};
const AccessorFormat kWeightsFormat{
    TINYGLTF_TYPE_VEC4,
    {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}},
    {}};
const AccessorFormat kMatrixFormat{TINYGLTF_TYPE_MAT4, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}}, {}};
const AccessorFormat kColourRgbFormat{
    TINYGLTF_TYPE_VEC3,
    {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}},
    {}};
const AccessorFormat kColourRgbaFormat{TINYGLTF_TYPE_VEC4, kColourRgbFormat.allowed, {}};
// Attributes qsgi does not use, read only to hold them to the specification's formats.
const AccessorFormat kTexcoordFormat{
    TINYGLTF_TYPE_VEC2,
    {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true}},
    {{TINYGLTF_COMPONENT_TYPE_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_BYTE, true},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_SHORT, false},
     {TINYGLTF_COMPONENT_TYPE_SHORT, true}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false}}};
const AccessorFormat kTangentFormat{
    TINYGLTF_TYPE_VEC4, {{TINYGLTF_COMPONENT_TYPE_FLOAT, false}},
    {{TINYGLTF_COMPONENT_TYPE_BYTE, true}, {TINYGLTF_COMPONENT_TYPE_SHORT, true}}};

const AccessorFormat kIndexFormat{
    TINYGLTF_TYPE_SCALAR,
    {{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false}, {TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false},
     {TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false}},
    {}};


// Textures and Materials

Vec3f vec3FromFactor(const std::vector<double>& f, Vec3f fallback) {
    return f.size() >= 3 ? Vec3f(float(f[0]), float(f[1]), float(f[2])) : fallback;
}

// The textures the materials read whole (base colour: albedo per texel), each image decoded once
// however many textures and materials share it. What a texture's sampler says comes with it.
class TextureImages {
public:
    TextureImages(const GltfDocument& document, const AccessorReader& reader) : document_(document), reader_(reader) {
        for (const tinygltf::Buffer& buffer : document.model.buffers) documentBytes_ += buffer.data.size();
        for (const tinygltf::Image& image : document.model.images) documentBytes_ += image.image.size();
    }

    // Texture `index` with its sampler, or why its image cannot be read; the image is added to
    // `decoded` (read, whatever came of it).
    std::pair<std::optional<Texture>, std::string> texture(int index, const std::string& usedBy, std::set<int>& decoded) {
        const tinygltf::Model& model = document_.model;
        if (index < 0 || index >= int(model.textures.size()))
            return {std::nullopt, "refers to texture " + std::to_string(index) + ", which does not exist"};
        const tinygltf::Texture& t = model.textures[size_t(index)];
        const int source = t.source;
        if (source < 0 || source >= int(model.images.size()))
            return {std::nullopt, gltfPlace("textures", index) + " has no image qsgi can read"};
        decoded.insert(source);
        auto [at, added] = images_.emplace(source, DecodedTexture());
        if (added) at->second = decode(source, usedBy);
        if (!at->second.image) return {std::nullopt, at->second.problem};
        Texture out;
        out.image = at->second.image;
        if (t.sampler >= 0 && t.sampler < int(model.samplers.size())) {
            const tinygltf::Sampler& sampler = model.samplers[size_t(t.sampler)];
            out.nearest = sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
            out.wrapS = wrapOf(sampler.wrapS);
            out.wrapT = wrapOf(sampler.wrapT);
        }
        return {out, ""};
    }
    size_t bytes() const {
        size_t total = 0;
        for (const auto& [image, decoded] : images_) total += decoded.image ? decoded.image->bytes() : 0;
        return total;
    }

private:
    static TextureWrap wrapOf(int mode) {
        return mode == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE     ? TextureWrap::ClampToEdge
               : mode == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT ? TextureWrap::MirroredRepeat
                                                               : TextureWrap::Repeat;
    }
    DecodedTexture decode(int source, const std::string& usedBy) const {
        const tinygltf::Image& image = document_.model.images[size_t(source)];
        const std::string imagePlace = gltfPlace("images", source);
        DecodedTexture out;
        // Decoded textures count against the memory the process may use: what the file's buffers
        // and encoded images hold while the scene is built, and what the images decoded so far
        // hold, is not there for the next.
        const uint64_t usable = usableMemory().bytes, held = saturatingAdd(documentBytes_, bytes());
        const uint64_t budget = usable > held ? usable - held : 0;
        if (image.bufferView >= 0) {
            const auto bytes = reader_.viewBytes(image.bufferView, usedBy + " -> " + imagePlace);
            out = decodeTextureImage(bytes.data, bytes.size, budget);
        } else if (!image.image.empty()) {
            out = decodeTextureImage(image.image.data(), image.image.size(), budget);
        } else {
            const auto why = document_.unreadableImages.find(source);
            out.problem = imagePlace + ".uri '" + image.uri.substr(0, 200) + "' " +
                          (why != document_.unreadableImages.end() ? why->second : "could not be read");
            return out;
        }
        if (!out.image) out.problem = imagePlace + " " + out.problem;
        return out;
    }

    const GltfDocument& document_;
    const AccessorReader& reader_;
    uint64_t documentBytes_ = 0;  // the file's buffers and encoded images, held by the document
    std::map<int, DecodedTexture> images_;  // by image index
};

// A number of a material's extension or textureInfo: finite, or the default when absent.
double extensionNumber(const tinygltf::Value& object, const char* key, double fallback, const std::string& file,
                       const std::string& place) {
    if (!object.Has(key)) return fallback;
    const tinygltf::Value& v = object.Get(key);
    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
        throw InputError(file, place + "." + key, "must be a finite number");
    return v.GetNumberAsDouble();
}

// How a material reads texture `info` (its texCoord, or the KHR_texture_transform's that
// overrides it, and that extension's offset, rotation and scale).
TextureSlot textureSlot(const tinygltf::TextureInfo& info, const std::string& file, const std::string& place) {
    TextureSlot slot;
    slot.texture = info.index;
    slot.texCoord = info.texCoord;
    auto transform = info.extensions.find("KHR_texture_transform");
    if (transform == info.extensions.end()) return slot;
    const tinygltf::Value& x = transform->second;
    const std::string at = place + ".extensions.KHR_texture_transform";
    // The texCoord override is checked with the primitive that reads it (addPrimitive).
    if (x.Has("texCoord") && x.Get("texCoord").IsNumber()) slot.texCoord = int(x.Get("texCoord").GetNumberAsDouble());
    for (const char* key : {"offset", "scale"}) {
        if (!x.Has(key)) continue;
        const tinygltf::Value& pair = x.Get(key);
        if (!pair.IsArray() || pair.ArrayLen() != 2 || !pair.Get(0).IsNumber() || !pair.Get(1).IsNumber() ||
            !std::isfinite(pair.Get(0).GetNumberAsDouble()) || !std::isfinite(pair.Get(1).GetNumberAsDouble()))
            throw InputError(file, at + "." + key, "must be two finite numbers");
        float* into = std::strcmp(key, "offset") == 0 ? slot.transform.offset : slot.transform.scale;
        into[0] = float(pair.Get(0).GetNumberAsDouble());
        into[1] = float(pair.Get(1).GetNumberAsDouble());
    }
    slot.transform.rotation = float(extensionNumber(x, "rotation", 0.0, file, at));
    return slot;
}

// Texture `info` as the material at `place` reads it, with its image added to `textures`; an
// unused slot, with a warning that the material keeps `factor` alone, when the image cannot be read.
TextureSlot readTexture(const tinygltf::TextureInfo& info, const std::string& place, const char* factor,
                        const std::string& file, Warnings& warnings, std::set<int>& decodedImages, TextureImages& images,
                        std::map<int, Texture>& textures) {
    const TextureSlot slot = textureSlot(info, file, place);
    auto [texture, problem] = images.texture(info.index, place, decodedImages);
    if (!texture) {
        warnings.add(file + ": " + place + ": " + problem + "; using " + factor + " alone");
        return TextureSlot();
    }
    textures.emplace(slot.texture, std::move(*texture));
    return slot;
}

Material convertMaterial(const GltfDocument& document, int index, const std::string& file,
                         Warnings& warnings, std::set<int>& decodedImages, TextureImages& images,
                         std::map<int, Texture>& textures) {
    const tinygltf::Material& m = document.model.materials[index];
    const std::string place = gltfPlace("materials", index);
    Material out;
    out.name = m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    out.albedo = vec3FromFactor(pbr.baseColorFactor, Vec3f(1.0f));
    out.alpha = pbr.baseColorFactor.size() >= 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
    // glTF 2.0: each factor lies in [0, 1] (a surface that reflects more than it receives would
    // make energy); refused, not clamped, so that the render is of the file as written.
    if (!isFinite(out.albedo) || out.albedo.x < 0 || out.albedo.y < 0 || out.albedo.z < 0 || maxComponent(out.albedo) > 1 ||
        !(out.alpha >= 0 && out.alpha <= 1))
        throw InputError(file, place + ".pbrMetallicRoughness.baseColorFactor", "must lie in [0, 1] (glTF 2.0)");
    if (pbr.baseColorTexture.index >= 0)
        out.baseColour = readTexture(pbr.baseColorTexture, place + ".pbrMetallicRoughness.baseColorTexture", "baseColorFactor",
                                     file, warnings, decodedImages, images, textures);
    // glTF 2.0 (§5.19): alphaMode OPAQUE (the default), MASK or BLEND; alphaCutoff ≥ 0, read
    // under MASK only.
    if (m.alphaMode == "MASK") out.alphaMode = AlphaMode::Mask;
    else if (m.alphaMode == "BLEND") out.alphaMode = AlphaMode::Blend;
    else if (!m.alphaMode.empty() && m.alphaMode != "OPAQUE")
        throw InputError(file, place + ".alphaMode", "is '" + m.alphaMode.substr(0, 40) + "', not OPAQUE, MASK or BLEND");
    if (!(m.alphaCutoff >= 0) || !std::isfinite(m.alphaCutoff))
        throw InputError(file, place + ".alphaCutoff", "must be a finite number of at least 0 (glTF 2.0)");
    out.alphaCutoff = float(m.alphaCutoff);
    out.doubleSided = m.doubleSided;
    // KHR_materials_transmission: transmissionFactor × transmissionTexture's R, in [0, 1]. qsgi
    // reads every surface as a dielectric (metallicFactor, 1 by default, is not modelled), so the
    // share passes in full (docs/inputs.md).
    auto transmission = m.extensions.find("KHR_materials_transmission");
    if (transmission != m.extensions.end()) {
        const std::string at = place + ".extensions.KHR_materials_transmission";
        const double factor = extensionNumber(transmission->second, "transmissionFactor", 0.0, file, at);
        if (!(factor >= 0 && factor <= 1))
            throw InputError(file, at + ".transmissionFactor", "must lie in [0, 1] (KHR_materials_transmission)");
        out.transmission = float(factor);
        if (transmission->second.Has("transmissionTexture") && factor > 0) {
            const tinygltf::Value& info = transmission->second.Get("transmissionTexture");
            const std::string texturePlace = at + ".transmissionTexture";
            tinygltf::TextureInfo textureInfo;
            textureInfo.index = info.Has("index") && info.Get("index").IsNumber() ? int(info.Get("index").GetNumberAsDouble()) : -1;
            textureInfo.texCoord = info.Has("texCoord") && info.Get("texCoord").IsNumber() ? int(info.Get("texCoord").GetNumberAsDouble()) : 0;
            if (info.Has("extensions") && info.Get("extensions").Has("KHR_texture_transform"))
                textureInfo.extensions["KHR_texture_transform"] = info.Get("extensions").Get("KHR_texture_transform");
            out.transmissionTexture = readTexture(textureInfo, texturePlace, "transmissionFactor", file, warnings, decodedImages,
                                                  images, textures);
        }
        if (factor > 0 && (m.extensions.count("KHR_materials_volume") || m.extensions.count("KHR_materials_ior")))
            warnings.add(file + ": " + place + ": KHR_materials_volume and KHR_materials_ior are ignored (a transmissive "
                                               "surface is a thin pane: light passes straight through)");
    }
    if (pbr.metallicRoughnessTexture.index >= 0 || m.normalTexture.index >= 0 || m.occlusionTexture.index >= 0)
        warnings.add(file + ": metallic/roughness, normal and occlusion maps are ignored (surfaces are Lambertian)");

    Vec3f emissive = vec3FromFactor(m.emissiveFactor, Vec3f(0.0f));
    if (m.emissiveTexture.index >= 0 && maxComponent(emissive) > 0)
        out.emissive = readTexture(m.emissiveTexture, place + ".emissiveTexture", "emissiveFactor", file, warnings,
                                   decodedImages, images, textures);
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
// The node's TRS properties (nullopt if it gives a matrix) and its local transform.
std::optional<NodeTrs> nodeTrs(const tinygltf::Node& n) {
    if (n.matrix.size() == 16) return std::nullopt;
    NodeTrs trs;
    if (n.translation.size() == 3) trs.translation = {n.translation[0], n.translation[1], n.translation[2]};
    if (n.scale.size() == 3) trs.scale = {n.scale[0], n.scale[1], n.scale[2]};
    if (n.rotation.size() == 4) trs.rotation = {n.rotation[0], n.rotation[1], n.rotation[2], n.rotation[3]};
    return trs;
}

// glTF 2.0 (§5.25, node): a matrix must decompose to TRS (animation targets and skins assume it): its last row 0 0 0 1 and no shear
// (trsDecompositionProblem, which transform files use too);
// a rotation is a unit quaternion (a zero one has no direction at all).
Transform nodeLocalTransform(const tinygltf::Node& n, const std::optional<NodeTrs>& trs, const std::string& file,
                             int index) {
    const std::string place = gltfPlace("nodes", index);
    if (n.rotation.size() == 4) {
        const double norm = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                                      n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
        if (!(norm > 1e-6))
            throw InputError(file, place + ".rotation", "is a zero quaternion (a rotation must be a unit quaternion)");
        if (!(std::fabs(norm - 1) <= kUnitQuaternionTolerance))
            throw InputError(file, place + ".rotation", "has length " + std::to_string(norm) + ", not 1 (a rotation must be a unit quaternion)");
    }
    const Transform t = trs ? trs->matrix() : Transform::fromColumnMajor(n.matrix.data());
    if (!t.isFinite()) throw InputError(file, place, "transform holds a non-finite number");
    if (!trs) {
        const std::string problem = trsDecompositionProblem(t);
        if (!problem.empty()) throw InputError(file, place + ".matrix", problem);
    }
    return t;
}

// The node tree. A node whose own transform breaks the rules is given the identity, and the
// error kept in `transformErrors` for the caller, who refuses it if the render uses the node
// and warns otherwise; a broken tree (a missing child, two parents, a cycle) is refused at once.
std::vector<SceneNode> buildHierarchy(const tinygltf::Model& model, const std::string& file,
                                      std::map<int, InputError>& transformErrors) {
    std::vector<SceneNode> nodes(model.nodes.size());
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        nodes[i].name = model.nodes[i].name;
        nodes[i].trs = nodeTrs(model.nodes[i]);
        try {
            nodes[i].local = nodeLocalTransform(model.nodes[i], nodes[i].trs, file, int(i));
        } catch (const InputError& e) {
            transformErrors.emplace(int(i), e);
            nodes[i].trs.reset();
        }
        for (int c : model.nodes[i].children) {
            if (c < 0 || c >= int(nodes.size()))
                throw InputError(file, gltfPlace("nodes", int(i)) + ".children", "refers to node " + std::to_string(c) + ", which does not exist");
            if (c == int(i)) throw InputError(file, gltfPlace("nodes", int(i)), "is its own child (the hierarchy has a cycle)");
            if (std::count(nodes[i].children.begin(), nodes[i].children.end(), c))
                throw InputError(file, gltfPlace("nodes", int(i)) + ".children", "lists node " + std::to_string(c) + " twice");
            if (nodes[c].parent >= 0 && nodes[c].parent != int(i))
                throw InputError(file, gltfPlace("nodes", c), "has two parents (nodes " + std::to_string(nodes[c].parent) +
                                                           " and " + std::to_string(i) + "); glTF nodes form a tree");
            nodes[c].parent = int(i);
            nodes[i].children.push_back(c);
        }
    }
    // A cycle without a root: following parents from any node must end. Each walk stops at a node
    // an earlier walk has shown to reach a root, so every node is walked once (a chain of any
    // depth costs its length, not its square).
    enum : uint8_t { kUnknown, kOnThisWalk, kReachesARoot };
    std::vector<uint8_t> state(nodes.size(), kUnknown);
    std::vector<int> walk;
    for (size_t i = 0; i < nodes.size(); ++i) {
        int p = int(i);
        for (; p >= 0 && state[size_t(p)] == kUnknown; p = nodes[size_t(p)].parent) {
            state[size_t(p)] = kOnThisWalk;
            walk.push_back(p);
        }
        if (p >= 0 && state[size_t(p)] == kOnThisWalk)
            throw InputError(file, gltfPlace("nodes", p), "is its own descendant (the hierarchy has a cycle)");
        for (int w : walk) state[size_t(w)] = kReachesARoot;
        walk.clear();
    }
    return nodes;
}

// Mesh Flattening
// The root of node n's tree (the hierarchy is acyclic: buildHierarchy refuses cycles).
int rootOf(const std::vector<SceneNode>& nodes, int n) {
    while (nodes[size_t(n)].parent >= 0) n = nodes[size_t(n)].parent;
    return n;
}

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
    SceneBuilder(const GltfDocument& document, const std::string& file, Warnings& warnings, const GltfReadOptions& options)
        : document_(document), model_(document.model), findings_(document.findings), file_(file), warnings_(warnings),
          options_(options), reader_(document, file) {}

    Scene build() {
        Scene scene;
        scene.sourcePath = file_;
        std::map<int, InputError> nodeErrors, materialErrors;
        scene.nodes = buildHierarchy(model_, file_, nodeErrors);
        for (size_t i = 0; i < model_.materials.size(); ++i) {
            try {
                scene.materials.push_back(
                    convertMaterial(document_, int(i), file_, warnings_, decodedImages_, images_, textures_));
            } catch (const InputError& e) {
                materialErrors.emplace(int(i), e);  // refused below if a rendered primitive uses it
                scene.materials.push_back(Material{"(unusable)", Vec3f(1.0f), Vec3f(0.0f)});
            }
        }
        // Every material's textures were decoded whether or not the render uses the material:
        // which views were read is learnt from here on, and the used images' views are added
        // by usedObjects.
        reader_.forgetReads();
        defaultMaterial_ = uint32_t(scene.materials.size());
        scene.materials.push_back(Material{"(default)", Vec3f(1.0f), Vec3f(0.0f)});

        if (model_.scenes.empty()) throw InputError(file_, "scenes", "the file has no scene to render");
        const int sceneIndex = model_.defaultScene >= 0 ? model_.defaultScene : 0;
        if (sceneIndex >= int(model_.scenes.size()))
            throw InputError(file_, "scene", "names scene " + std::to_string(sceneIndex) + ", which does not exist");
        const auto& roots = model_.scenes[sceneIndex].nodes;
        if (roots.empty()) throw InputError(file_, gltfPlace("scenes", sceneIndex), "has no nodes: nothing to render");

        const std::vector<Transform> world = scene.worldTransforms(scene.restLocals());
        std::vector<uint8_t> visited(scene.nodes.size(), 0);
        std::vector<int> stack;
        for (int r : roots) {
            if (r < 0 || r >= int(scene.nodes.size()))
                throw InputError(file_, gltfPlace("scenes", sceneIndex) + ".nodes", "refers to node " + std::to_string(r) + ", which does not exist");
            if (scene.nodes[r].parent >= 0)
                throw InputError(file_, gltfPlace("scenes", sceneIndex) + ".nodes", "lists node " + std::to_string(r) + ", which is not a root");
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
        scene.animations = readGltfAnimations(model_, reader_, file_, warnings_);
        // glTF 2.0 (§3.7.3.1): a rendered skin's joints are in the rendered scene.
        for (const auto& [gltfSkin, sceneSkin] : skinOf_) {
            const int root = rootOf(scene.nodes, scene.skins[size_t(sceneSkin)].joints[0]);
            if (!visited[size_t(root)])
                throw InputError(file_, gltfPlace("skins", gltfSkin) + ".joints",
                                 "hang from node " + std::to_string(root) + ", which is not in the rendered scene");
        }
        // What the render used is now known: errors there are refusals, errors elsewhere warnings.
        std::vector<uint8_t> usedNodes = visited;
        for (const auto& [gltfSkin, sceneSkin] : skinOf_)
            for (int j : scene.skins[size_t(sceneSkin)].joints) usedNodes[size_t(j)] = 1;
        for (const auto& [n, e] : nodeErrors)
            if (usedNodes[size_t(n)]) throw e;
        for (const auto& [m, e] : materialErrors)
            if (usedMaterials_.count(m)) throw e;
        for (const auto& [n, e] : nodeErrors) unusedObjectError(e, gltfPlace("nodes", n));
        for (const auto& [m, e] : materialErrors) unusedObjectError(e, gltfPlace("materials", m));
        // Before the unused objects are checked: reading them marks accessors and views as read.
        const UsedObjects used = usedObjects(scene, usedNodes);
        checkUnusedObjects(scene, usedNodes);
        for (const GltfFinding& f : findings_) {
            const InputError e(file_, f.place, f.problem);
            if (used.contains(f.object)) throw e;
            unusedObjectError(e, f.object);
        }
        // An image whose file could not be read: the material decoding it has warned and kept its
        // factor (docs/inputs.md); one no material decodes is an object nothing reads.
        for (const auto& [image, why] : document_.unreadableImages)
            if (!decodedImages_.count(image))
                unusedObjectError(InputError(file_, gltfPlace("images", image) + ".uri",
                                             "'" + model_.images[size_t(image)].uri.substr(0, 200) + "' " + why),
                                  gltfPlace("images", image));
        keepUsedTextures(scene);
        scene.finalize();
        checkSceneExtent(scene.positions, scene.bounds(), file_, "nodes");
        return scene;
    }

private:
    // The scene keeps the textures its materials read; the images only unused materials read are
    // let go. Materials the render does not use lose their textures (nothing reads them).
    void keepUsedTextures(Scene& scene) {
        auto set = std::make_shared<TextureSet>(model_.textures.size());
        for (size_t i = 0; i < scene.materials.size(); ++i)
            for (TextureSlot* slot :
                 {&scene.materials[i].baseColour, &scene.materials[i].emissive, &scene.materials[i].transmissionTexture}) {
                if (!slot->used()) continue;
                if (!usedMaterials_.count(int(i))) {
                    *slot = TextureSlot();
                    continue;
                }
                (*set)[size_t(slot->texture)] = textures_.at(slot->texture);
            }
        textures_.clear();
        scene.textures = std::move(set);
    }

    // An error in an object the render does not use (glTF objects nothing in the default scene
    // reaches): a warning naming it, or, under --strict, a refusal.
    // object "": a slip in the document itself that leaves it readable (an empty top-level
    // array, a byte-order mark).
    void unusedObjectError(const InputError& e, const std::string& object) {
        if (options_.strict)
            throw InputError(e.file(), e.place(), e.problem() + (object.empty() ? " (--strict refuses it)"
                                                                                 : " (" + object + " is not in the rendered scene; --strict refuses it)"));
        warnings_.add(std::string(e.what()) + (object.empty() ? " (the file is read all the same)"
                                                              : " (" + object + " is not in the rendered scene, so it is ignored)"));
    }

    // Which top-level objects the render read, by name ("nodes[3]"); the document itself ("")
    // is not one of them: what is wrong there (an empty top-level array) is in no object it reads.
    struct UsedObjects {
        std::set<std::string> names;
        bool contains(const std::string& object) const { return names.count(object) > 0; }
    };
    UsedObjects usedObjects(const Scene& scene, const std::vector<uint8_t>& usedNodes) const {
        UsedObjects used;
        auto add = [&](const char* array, int index) { used.names.insert(gltfPlace(array, index)); };
        for (size_t n = 0; n < usedNodes.size(); ++n)
            if (usedNodes[n]) add("nodes", int(n));
        for (int m : usedMeshes_) add("meshes", m);
        for (int m : usedMaterials_) {
            add("materials", m);
            const tinygltf::Material& material = model_.materials[size_t(m)];
            // The textures whose colours the render reads, and their images and samplers.
            for (int t : {material.pbrMetallicRoughness.baseColorTexture.index, material.emissiveTexture.index}) {
                if (t < 0 || t >= int(model_.textures.size())) continue;
                add("textures", t);
                const int image = model_.textures[size_t(t)].source;
                if (image >= 0 && image < int(model_.images.size())) {
                    add("images", image);
                    const int view = model_.images[size_t(image)].bufferView;
                    if (view >= 0 && view < int(model_.bufferViews.size())) {
                        add("bufferViews", view);
                        add("buffers", model_.bufferViews[size_t(view)].buffer);
                    }
                }
                if (model_.textures[size_t(t)].sampler >= 0) add("samplers", model_.textures[size_t(t)].sampler);
            }
        }
        for (size_t a = 0; a < model_.accessors.size(); ++a)
            if (reader_.wasRead(int(a))) add("accessors", int(a));
        for (size_t v = 0; v < model_.bufferViews.size(); ++v)
            if (reader_.viewWasRead(int(v))) {
                add("bufferViews", int(v));
                add("buffers", model_.bufferViews[v].buffer);
            }
        for (const auto& [gltfSkin, sceneSkin] : skinOf_) add("skins", gltfSkin);
        for (int l : usedLights_) add("KHR_lights_punctual.lights", l);
        for (size_t c = 0; c < scene.cameras.size(); ++c)
            if (scene.cameras[c]) add("cameras", int(c));
        for (size_t a = 0; a < model_.animations.size(); ++a) add("animations", int(a));  // all are read
        add("scenes", model_.defaultScene >= 0 ? model_.defaultScene : 0);
        return used;
    }

    // The nodes, meshes, skins, cameras and accessors the default scene does not reach are
    // checked by the same code that reads the used ones, into a scratch scene that is thrown away.
    void checkUnusedObjects(const Scene& scene, const std::vector<uint8_t>& usedNodes) {
        // A buffer without data is valid while nothing reads it: here reads through it give zeros.
        struct Tolerate {
            const AccessorReader& reader;
            explicit Tolerate(const AccessorReader& r) : reader(r) { reader.tolerateAbsentData(true); }
            ~Tolerate() { reader.tolerateAbsentData(false); }
        } tolerate(reader_);
        // The scratch scene has skins of its own: the real scene's map of skins is set aside
        // (and put back however this ends), as are the sets of used meshes and materials; what
        // addInfluences repairs there goes unwarned (the render does not read it).
        struct SetAside {
            SceneBuilder& builder;
            std::map<int, int> skins;
            std::set<int> meshes, materials;
            explicit SetAside(SceneBuilder& b)
                : builder(b), skins(std::move(b.skinOf_)), meshes(b.usedMeshes_), materials(b.usedMaterials_) {
                builder.skinOf_.clear();
                builder.readingUnusedObjects_ = true;
            }
            ~SetAside() {
                builder.readingUnusedObjects_ = false;
                builder.skinOf_ = std::move(skins);
                builder.usedMeshes_ = std::move(meshes);
                builder.usedMaterials_ = std::move(materials);
            }
        } setAside(*this);
        Scene scratch;
        scratch.materials = scene.materials;
        scratch.nodes = scene.nodes;
        const std::map<int, int>& usedSkins = setAside.skins;
        const std::set<int>& usedMeshes = setAside.meshes;
        for (size_t n = 0; n < model_.nodes.size(); ++n) {
            if (usedNodes[n]) continue;
            try {
                visitNode(scratch, int(n), Transform());
            } catch (const InputError& e) {
                unusedObjectError(e, gltfPlace("nodes", int(n)));
            }
        }
        for (size_t m = 0; m < model_.meshes.size(); ++m) {
            if (usedMeshes.count(int(m))) continue;
            try {
                checkMeshShape(int(m));
                for (size_t p = 0; p < model_.meshes[m].primitives.size(); ++p)
                    addPrimitive(scratch, 0, Transform(), model_.meshes[m].primitives[p],
                                 gltfPlace("meshes", int(m)) + "." + gltfPlace("primitives", int(p)), -1, {});
            } catch (const InputError& e) {
                unusedObjectError(e, gltfPlace("meshes", int(m)));
            }
        }
        for (size_t s = 0; s < model_.skins.size(); ++s) {
            if (usedSkins.count(int(s))) continue;
            try {
                addSkin(scratch, int(s), gltfPlace("skins", int(s)));
            } catch (const InputError& e) {
                unusedObjectError(e, gltfPlace("skins", int(s)));
            }
        }
        for (size_t c = 0; c < model_.cameras.size(); ++c) {
            if (scene.cameras[c]) continue;
            try {
                readLens(int(c));
            } catch (const InputError& e) {
                unusedObjectError(e, gltfPlace("cameras", int(c)));
            }
        }
        for (size_t v = 0; v < model_.bufferViews.size(); ++v) {
            if (reader_.viewWasRead(int(v))) continue;
            try {
                reader_.checkUnreadView(int(v));
            } catch (const InputError& e) {
                unusedObjectError(e, gltfPlace("bufferViews", int(v)));
            }
        }
        for (size_t a = 0; a < model_.accessors.size(); ++a) {
            if (reader_.wasRead(int(a))) continue;
            try {
                reader_.checkUnread(int(a), gltfPlace("accessors", int(a)));
            } catch (const InputError& e) {
                unusedObjectError(e, gltfPlace("accessors", int(a)));
            }
        }
    }

    // glTF 2.0 (§3.7.2, §3.7.2.2): a mesh has at least one primitive, every primitive as many
    // morph targets, and the mesh's default weights, where given, one for each.
    void checkMeshShape(int meshIndex) const {
        const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
        if (mesh.primitives.empty())
            throw InputError(file_, gltfPlace("meshes", meshIndex) + ".primitives", "is empty (glTF requires at least one primitive)");
        for (size_t p = 0; p < mesh.primitives.size(); ++p)
            if (mesh.primitives[p].targets.size() != mesh.primitives[0].targets.size())
                throw InputError(file_, gltfPlace("meshes", meshIndex) + "." + gltfPlace("primitives", int(p)) + ".targets",
                                 "has " + std::to_string(mesh.primitives[p].targets.size()) +
                                     " morph targets but primitive 0 has " + std::to_string(mesh.primitives[0].targets.size()));
        if (!mesh.weights.empty() && mesh.weights.size() != mesh.primitives[0].targets.size())
            throw InputError(file_, gltfPlace("meshes", meshIndex) + ".weights",
                             "has " + std::to_string(mesh.weights.size()) + " weights for " +
                                 std::to_string(mesh.primitives[0].targets.size()) + " morph targets");
    }

    void visitNode(Scene& scene, int n, const Transform& world) {
        const tinygltf::Node& node = model_.nodes[n];
        if (node.mesh >= 0) {
            if (node.mesh >= int(model_.meshes.size()))
                throw InputError(file_, gltfPlace("nodes", n) + ".mesh", "refers to mesh " + std::to_string(node.mesh) + ", which does not exist");
            const tinygltf::Mesh& mesh = model_.meshes[node.mesh];
            usedMeshes_.insert(node.mesh);
            checkMeshShape(node.mesh);
            const int skin = node.skin >= 0 ? addSkin(scene, node.skin, gltfPlace("nodes", n) + ".skin") : -1;
            // Morph target weights: the node's, else the mesh's, else zeros (glTF 2.0 §3.7.2.2).
            const std::vector<double>& weights = !node.weights.empty() ? node.weights : mesh.weights;
            if (!node.weights.empty() && node.weights.size() != mesh.primitives[0].targets.size())
                throw InputError(file_, gltfPlace("nodes", n) + ".weights",
                                 "has " + std::to_string(node.weights.size()) + " weights for " +
                                     std::to_string(mesh.primitives[0].targets.size()) + " morph targets");
            for (size_t p = 0; p < mesh.primitives.size(); ++p) {
                const std::string place = gltfPlace("meshes", node.mesh) + "." + gltfPlace("primitives", int(p));
                const size_t before = scene.instances.size();
                addPrimitive(scene, n, world, mesh.primitives[p], place, skin, weights);
                if (scene.instances.size() > before) {  // not skipped (points, lines, no POSITION)
                    scene.instances.back().mesh = node.mesh;
                    scene.instances.back().primitive = int(p);
                }
            }
        }
        // glTF 2.0 (§5.25): a skin or morph weights belong to a node's mesh.
        if (node.mesh < 0 && node.skin >= 0)
            throw InputError(file_, gltfPlace("nodes", n) + ".skin", "is given on a node without a mesh");
        if (node.mesh < 0 && !node.weights.empty())
            throw InputError(file_, gltfPlace("nodes", n) + ".weights", "are given on a node without a mesh");
        if (node.camera >= 0) addCamera(scene, n, world);
        auto light = node.extensions.find("KHR_lights_punctual");
        if (light != node.extensions.end() && light->second.Has("light")) addLight(scene, n, world, light->second.Get("light"));
    }

    // glTF 2.0 (§3.7.2.1): attribute names are the spec's semantics or custom ones starting
    // with "_"; indexed sets (TEXCOORD_n, COLOR_n, JOINTS_n, WEIGHTS_n) count up from 0 without
    // gaps; JOINTS_n comes with WEIGHTS_n; a morph target moves only attributes the primitive has.
    void checkAttributeNames(const tinygltf::Primitive& prim, const std::string& place) const {
        std::map<std::string, std::set<int>> sets;
        for (const auto& [name, accessor] : prim.attributes) {
            if (accessor >= 0 && accessor < int(model_.accessors.size()) &&
                model_.accessors[size_t(accessor)].componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                throw InputError(file_, place + ".attributes." + name, "has UNSIGNED_INT components, which glTF allows "
                                                                       "for indices only");
            if (name == "POSITION" || name == "NORMAL" || name == "TANGENT" || (!name.empty() && name[0] == '_')) continue;
            const size_t underscore = name.rfind('_');
            const std::string family = underscore == std::string::npos ? name : name.substr(0, underscore);
            const std::string number = underscore == std::string::npos ? "" : name.substr(underscore + 1);
            const bool counted = !number.empty() && number.size() < 6 &&
                                 number.find_first_not_of("0123456789") == std::string::npos && (number == "0" || number[0] != '0');
            if (!counted || (family != "TEXCOORD" && family != "COLOR" && family != "JOINTS" && family != "WEIGHTS"))
                throw InputError(file_, place + ".attributes." + name,
                                 "is no attribute glTF defines (custom attributes start with '_')");
            sets[family].insert(std::stoi(number));
        }
        for (const auto& [family, numbers] : sets)
            if (*numbers.rbegin() != int(numbers.size()) - 1)
                throw InputError(file_, place + ".attributes",
                                 "has " + family + "_" + std::to_string(*numbers.rbegin()) + " without every " + family +
                                     " set below it (glTF numbers them from 0 without gaps)");
        if (sets["JOINTS"] != sets["WEIGHTS"])
            throw InputError(file_, place + ".attributes", "has JOINTS_n and WEIGHTS_n sets that do not pair up");
        for (size_t t = 0; t < prim.targets.size(); ++t)
            for (const auto& [name, accessor] : prim.targets[t])
                if (!prim.attributes.count(name))
                    throw InputError(file_, place + "." + gltfPlace("targets", int(t)) + "." + name,
                                     "morphs an attribute the primitive does not have");
    }

    // Attributes the render does not use still follow the rules of their semantics (glTF 2.0
    // §3.7.2.1): their formats, and vertex colours within [0, 1].
    void checkOtherAttributes(const tinygltf::Primitive& prim, const std::string& place) const {
        for (const auto& [name, accessor] : prim.attributes) {
            if (name.rfind("TEXCOORD_", 0) == 0) reader_.read(accessor, place + ".attributes." + name, kTexcoordFormat);
            if (name == "TANGENT") reader_.read(accessor, place + ".attributes." + name, kTangentFormat);
            if (name.rfind("COLOR_", 0) != 0) continue;
            const bool rgba = accessor >= 0 && accessor < int(model_.accessors.size()) &&
                              model_.accessors[size_t(accessor)].type == TINYGLTF_TYPE_VEC4;
            const AccessorData colours = reader_.read(accessor, place + ".attributes." + name, rgba ? kColourRgbaFormat : kColourRgbFormat);
            for (size_t i = 0; i < colours.values.size(); ++i)
                if (colours.values[i] < 0 || colours.values[i] > 1)
                    throw InputError(file_, place + ".attributes." + name,
                                     "vertex " + std::to_string(i / size_t(colours.components)) + " has a component " +
                                         std::to_string(colours.values[i]) + " outside [0, 1]");
        }
    }

    void addPrimitive(Scene& scene, int nodeIndex, const Transform& world, const tinygltf::Primitive& prim,
                      const std::string& place, int skin, const std::vector<double>& morphWeights) {
        checkAttributeNames(prim, place);
        checkOtherAttributes(prim, place);
        if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            prim.mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            warnings_.add(file_ + ": point and line primitives are skipped");
            return;
        }
        auto pos = prim.attributes.find("POSITION");
        if (pos == prim.attributes.end()) {
            // Valid glTF: "client implementations should skip" a primitive without positions.
            warnings_.add(file_ + ": " + place + " has no POSITION attribute and is skipped");
            return;
        }
        const AccessorData positions = reader_.read(pos->second, place + ".attributes.POSITION", kPositionFormat);
        // glTF 2.0 (§5.1.3): a POSITION accessor states its bounds (min and max), which viewers use.
        if (pos->second >= 0 && size_t(pos->second) < model_.accessors.size() &&
            (model_.accessors[size_t(pos->second)].minValues.size() != 3 || model_.accessors[size_t(pos->second)].maxValues.size() != 3))
            throw InputError(file_, gltfPlace("accessors", pos->second),
                             "is a POSITION accessor without min and max (glTF requires both, 3 numbers each)");
                const size_t vertexCount = positions.count;

        std::optional<AccessorData> normals;
        auto nrm = prim.attributes.find("NORMAL");
        if (nrm != prim.attributes.end()) {
            normals = reader_.read(nrm->second, place + ".attributes.NORMAL", kNormalFormat);
            if (normals->count != vertexCount)
                throw InputError(file_, place + ".attributes.NORMAL",
                                 "has " + std::to_string(normals->count) + " elements but POSITION has " +
                                     std::to_string(vertexCount) + " (attribute arrays must have equal lengths)");
            // Unit length, within the glTF-Validator's own tolerance, where the file states them.
            const size_t stated = reader_.hasData(nrm->second) ? normals->count : 0;
            for (size_t i = 0; i < stated; ++i) {
                const double len = length(Vec3d((*normals)(i, 0), (*normals)(i, 1), (*normals)(i, 2)));
                if (!(std::fabs(len - 1) <= kUnitVectorTolerance))
                    throw InputError(file_, place + ".attributes.NORMAL", "vertex " + std::to_string(i) + "'s normal has length " +
                                                                              std::to_string(len) + ", not 1 (glTF requires unit normals)");
            }
        }
        for (const auto& [name, accessor] : prim.attributes) {
            if (accessor >= 0 && accessor < int(model_.accessors.size()) && model_.accessors[accessor].count != vertexCount)
                throw InputError(file_, place + ".attributes." + name,
                                 "has " + std::to_string(model_.accessors[accessor].count) + " elements but POSITION has " +
                                     std::to_string(vertexCount) + " (attribute arrays must have equal lengths)");
        }

        std::vector<uint32_t> indices;
        if (prim.indices >= 0) {
            // glTF 2.0 (§3.6.2.4): indices are tightly packed; their bufferView has no byteStride.
            if (prim.indices < int(model_.accessors.size())) {
                const int view = model_.accessors[size_t(prim.indices)].bufferView;
                if (view >= 0 && view < int(model_.bufferViews.size()) && model_.bufferViews[size_t(view)].byteStride != 0)
                    throw InputError(file_, gltfPlace("bufferViews", view) + ".byteStride",
                                     "is set on a view that holds indices (" + place + ".indices), which glTF forbids");
            }
            const AccessorData idx = reader_.readUnbounded(prim.indices, place + ".indices", kIndexFormat);
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
            reader_.checkDeclaredBounds(prim.indices, idx, place + ".indices");
        } else {
            indices.resize(vertexCount);
            for (size_t i = 0; i < vertexCount; ++i) indices[i] = uint32_t(i);
        }
        // glTF 2.0 (§5.24.4): TRIANGLES takes three vertices a triangle; a remainder is no triangle
        // the file meant, so it is refused rather than dropped.
        if (prim.mode == TINYGLTF_MODE_TRIANGLES && indices.size() % 3 != 0)
            throw InputError(file_, place + (prim.indices >= 0 ? ".indices" : ".attributes.POSITION"),
                             "has " + std::to_string(indices.size()) + " vertices, not a multiple of 3 (TRIANGLES)");
        std::vector<uint32_t> tri = triangleIndices(prim.mode, indices);
        if (scene.positions.size() + vertexCount > (size_t(1) << 31))
            throw InputError(file_, place, "the scene exceeds 2^31 vertices");

        uint32_t material = defaultMaterial_;
        if (prim.material >= 0) {
            if (prim.material >= int(model_.materials.size()))
                throw InputError(file_, place + ".material", "refers to material " + std::to_string(prim.material) + ", which does not exist");
            material = uint32_t(prim.material);
            usedMaterials_.insert(prim.material);
            // Every texture of the material reads a TEXCOORD_n set the primitive has (glTF 2.0
            // §3.9.6): its textureInfo's texCoord, or the KHR_texture_transform's that overrides it.
            const tinygltf::Material& m = model_.materials[size_t(prim.material)];
            struct TextureUse {
                const char* name;
                int index, texCoord;
                const tinygltf::ExtensionMap& extensions;
            };
            const auto& pbr = m.pbrMetallicRoughness;
            const TextureUse textures[] = {
                {"pbrMetallicRoughness.baseColorTexture", pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                 pbr.baseColorTexture.extensions},
                {"pbrMetallicRoughness.metallicRoughnessTexture", pbr.metallicRoughnessTexture.index,
                 pbr.metallicRoughnessTexture.texCoord, pbr.metallicRoughnessTexture.extensions},
                {"emissiveTexture", m.emissiveTexture.index, m.emissiveTexture.texCoord, m.emissiveTexture.extensions},
                {"normalTexture", m.normalTexture.index, m.normalTexture.texCoord, m.normalTexture.extensions},
                {"occlusionTexture", m.occlusionTexture.index, m.occlusionTexture.texCoord, m.occlusionTexture.extensions}};
            const int textureCount = int(model_.textures.size());  // a texture that does not exist is a finding
            for (const TextureUse& t : textures) {
                if (t.index < 0 || t.index >= textureCount) continue;
                std::string reader = gltfPlace("materials", prim.material) + "." + t.name;
                int texCoord = t.texCoord;
                auto transform = t.extensions.find("KHR_texture_transform");
                if (transform != t.extensions.end() && transform->second.Has("texCoord")) {
                    reader += ".extensions.KHR_texture_transform.texCoord";
                    const tinygltf::Value& v = transform->second.Get("texCoord");
                    const double set = v.IsNumber() ? v.GetNumberAsDouble() : -1;
                    if (!(set >= 0 && set <= 2147483647.0 && std::floor(set) == set))
                        throw InputError(file_, reader, "must be a non-negative integer (the TEXCOORD set the transformed texture reads)");
                    texCoord = int(set);
                }
                if (!prim.attributes.count("TEXCOORD_" + std::to_string(texCoord)))
                    throw InputError(file_, place, "has no TEXCOORD_" + std::to_string(texCoord) + ", which " + reader + " reads");
            }
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
        scene.addInstance(nodeIndex, std::move(objectPositions), std::move(objectNormals), tri, material, &world);
        addSurfaceAttributes(scene, prim, place, scene.materials[material]);
        MeshInstance& instance = scene.instances.back();
        if (skin >= 0) addInfluences(scene, instance, prim, place, skin);
        addMorphTargets(instance, prim, place, morphWeights, normals.has_value());
    }

    // The per-vertex data the material reads (issue 57), into the scene's arrays for the block the
    // last addInstance added: the TEXCOORD_n set its base colour texture reads, and COLOR_0 (RGB
    // or RGBA, float or normalised integers; checked by checkOtherAttributes), linear as glTF says.
    void addSurfaceAttributes(Scene& scene, const tinygltf::Primitive& prim, const std::string& place,
                              const Material& material) {
        const size_t first = scene.instances.back().firstVertex, count = scene.instances.back().vertexCount;
        for (const TextureSlot* slot : {&material.baseColour, &material.emissive, &material.transmissionTexture}) {
            if (!slot->used()) continue;
            const size_t set = size_t(slot->texCoord);
            const std::string name = "TEXCOORD_" + std::to_string(set);
            const auto attribute = prim.attributes.find(name);
            if (attribute == prim.attributes.end())
                throw InputError(file_, place, "has no " + name + ", which a texture of its material reads");
            const AccessorData uv = reader_.read(attribute->second, place + ".attributes." + name, kTexcoordFormat);
            if (scene.vertexTexCoords.size() <= set) scene.vertexTexCoords.resize(set + 1);
            std::vector<TexCoord>& into = scene.vertexTexCoords[set];
            into.resize(scene.positions.size());
            for (size_t i = 0; i < count && i < uv.count; ++i) into[first + i] = {float(uv(i, 0)), float(uv(i, 1))};
        }
        auto colour = prim.attributes.find("COLOR_0");
        if (colour == prim.attributes.end()) return;
        const bool rgba = colour->second >= 0 && colour->second < int(model_.accessors.size()) &&
                          model_.accessors[size_t(colour->second)].type == TINYGLTF_TYPE_VEC4;
        const AccessorData c = reader_.read(colour->second, place + ".attributes.COLOR_0", rgba ? kColourRgbaFormat : kColourRgbFormat);
        scene.vertexColours.resize(scene.positions.size(), Rgba{1, 1, 1, 1});
        for (size_t i = 0; i < count && i < c.count; ++i)
            scene.vertexColours[first + i] = {float(c(i, 0)), float(c(i, 1)), float(c(i, 2)), rgba ? float(c(i, 3)) : 1.0f};
    }

    // glTF 2.0 (§3.7.3.1): a skin's joints hang from one common root, and its skeleton, if
    // given, is an ancestor of (or is) every joint. The nodes' parents are known (buildHierarchy).
    void checkJointHierarchy(const Scene& scene, int index, const tinygltf::Skin& source) const {
        const std::string place = gltfPlace("skins", index);
        auto descendsFrom = [&](int n, int ancestor) {
            for (; n >= 0; n = scene.nodes[size_t(n)].parent)
                if (n == ancestor) return true;
            return false;
        };
        const int root = rootOf(scene.nodes, source.joints[0]);
        for (int j : source.joints)
            if (rootOf(scene.nodes, j) != root)
                throw InputError(file_, place + ".joints", "holds nodes " + std::to_string(source.joints[0]) + " and " +
                                                               std::to_string(j) + ", which share no root (glTF requires one)");
        if (source.skeleton >= 0 && source.skeleton < int(scene.nodes.size()))
            for (int j : source.joints)
                if (!descendsFrom(j, source.skeleton))
                    throw InputError(file_, place + ".skeleton", "node " + std::to_string(source.skeleton) +
                                                                     " is not an ancestor of joint node " + std::to_string(j));
    }

    // The Scene::skins index of glTF skin `index`, read on first use.
    int addSkin(Scene& scene, int index, const std::string& usedBy) {
        if (index >= int(model_.skins.size()))
            throw InputError(file_, usedBy, "refers to skin " + std::to_string(index) + ", which does not exist");
        auto known = skinOf_.find(index);
        if (known != skinOf_.end()) return known->second;
        const tinygltf::Skin& source = model_.skins[size_t(index)];
        const std::string place = gltfPlace("skins", index);
        Skin skin;
        skin.name = source.name;
        if (source.joints.empty()) throw InputError(file_, place + ".joints", "is empty");
        for (int j : source.joints) {
            if (j < 0 || j >= int(model_.nodes.size()))
                throw InputError(file_, place + ".joints", "refers to node " + std::to_string(j) + ", which does not exist");
            skin.joints.push_back(j);
        }
        checkJointHierarchy(scene, index, source);
        skin.inverseBind.assign(skin.joints.size(), Transform());
        if (source.inverseBindMatrices >= 0) {
            const AccessorData m = reader_.read(source.inverseBindMatrices, place + ".inverseBindMatrices", kMatrixFormat);
            if (m.count < skin.joints.size())
                throw InputError(file_, place + ".inverseBindMatrices", "has " + std::to_string(m.count) + " matrices for " +
                                                                          std::to_string(skin.joints.size()) + " joints");
            const bool stated = reader_.hasData(source.inverseBindMatrices);  // else zeros by default
            for (size_t j = 0; j < skin.joints.size(); ++j) {
                skin.inverseBind[j] = Transform::fromColumnMajor(&m.values[16 * j]);
                if (!stated) continue;
                // glTF 2.0 (§5.28): an inverse bind matrix is affine. Only its last row is checked:
                // a joint under a non-uniformly scaled parent legitimately has a sheared one.
                const Transform& ibm = skin.inverseBind[j];
                if (ibm.at(3, 0) != 0 || ibm.at(3, 1) != 0 || ibm.at(3, 2) != 0 || ibm.at(3, 3) != 1)
                    throw InputError(file_, place + ".inverseBindMatrices",
                                     "matrix " + std::to_string(j) + " has a last row other than 0 0 0 1 (glTF requires "
                                     "an affine matrix)");
            }
        }
        scene.skins.push_back(std::move(skin));
        return skinOf_[index] = int(scene.skins.size()) - 1;
    }

    // JOINTS_n / WEIGHTS_n of a skinned primitive. glTF 2.0 (§3.7.3.3) makes these a MUST, refused
    // always: no negative weight, no joint named twice with non-zero weights, every joint index
    // naming a joint of the skin (also where its weight is 0), and normalized-integer weights
    // summing to 255 or 65535 before normalization. Float weights SHOULD sum as close to 1 as
    // reasonably possible: sums within the glTF-Validator's tolerance (2e-7 a non-zero weight) are
    // normalised silently; others (CesiumMan's reach 0.185) are repaired as three.js's
    // normalizeSkinWeights does, renormalised to sum 1 and a vertex whose weights are all zero
    // given weight 1 on its first joint (the spec ignores a skinned mesh's node, so there is
    // nothing else to follow), with one warning per accessor saying how many vertices were
    // repaired; --strict refuses them. Accessors without data (zeros by default) have no sums to
    // judge, as for the validator: their vertices are repaired alike, with the warning, but not
    // refused.
    void addInfluences(const Scene& scene, MeshInstance& instance, const tinygltf::Primitive& prim,
                       const std::string& place, int skin) {
        const size_t joints = scene.skins[size_t(skin)].joints.size();
        std::vector<AccessorData> jointSets, weightSets;
        std::vector<int> weightAccessors;
        bool weightsStated = true;  // else zeros by default: no sums to judge
        bool floatWeights = true;   // else normalized integers somewhere, whose sums are a MUST
        for (int set = 0;; ++set) {
            auto j = prim.attributes.find("JOINTS_" + std::to_string(set));
            auto w = prim.attributes.find("WEIGHTS_" + std::to_string(set));
            if (j == prim.attributes.end() && w == prim.attributes.end()) break;
            if (j == prim.attributes.end() || w == prim.attributes.end())
                throw InputError(file_, place + ".attributes", "has JOINTS_" + std::to_string(set) + " or WEIGHTS_" +
                                                                   std::to_string(set) + " without the other");
            jointSets.push_back(reader_.read(j->second, place + ".attributes." + j->first, kJointsFormat));
            weightSets.push_back(reader_.read(w->second, place + ".attributes." + w->first, kWeightsFormat));
            weightAccessors.push_back(w->second);
            weightsStated = weightsStated && reader_.hasData(w->second) && reader_.hasData(j->second);
            floatWeights = floatWeights && model_.accessors[size_t(w->second)].componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
        }
        if (jointSets.empty())
            throw InputError(file_, place + ".attributes",
                             "has no JOINTS_0 and WEIGHTS_0, yet its node has a skin (glTF requires them)");
        const size_t n = instance.vertexCount;
        instance.skin = skin;
        instance.influences = int(4 * jointSets.size());
        instance.skinJoints.assign(n * size_t(instance.influences), 0);
        instance.skinWeights.assign(n * size_t(instance.influences), 0.0f);
        // The weights as messages name them: "….attributes.WEIGHTS_0" and "accessor 5" (or every set).
        std::string weightsPlace = place + ".attributes.WEIGHTS_0", accessorNames = "accessor ";
        if (weightSets.size() > 1) weightsPlace += " to WEIGHTS_" + std::to_string(weightSets.size() - 1);
        if (weightSets.size() > 1) accessorNames = "accessors ";
        for (size_t s = 0; s < weightAccessors.size(); ++s)
            accessorNames += (s ? ", " : "") + std::to_string(weightAccessors[s]);
        size_t repaired = 0, allZero = 0, firstRepaired = 0;
        float firstSum = 0, lowest = 0, highest = 0;
        std::vector<double> namedJoints;
        for (size_t v = 0; v < n; ++v) {
            double total = 0;
            // The sum as the glTF-Validator forms it (in float), and its tolerance: 2e-7 a weight.
            float floatTotal = 0, tolerance = 0;
            namedJoints.clear();
            for (size_t s = 0; s < jointSets.size(); ++s)
                for (int k = 0; k < 4; ++k) {
                    const double joint = jointSets[s](v, k), weight = weightSets[s](v, k);
                    if (weight < 0)
                        throw InputError(file_, place + ".attributes.WEIGHTS_" + std::to_string(s), "holds a negative weight");
                    if (weight > 0) {
                        if (weightsStated && std::find(namedJoints.begin(), namedJoints.end(), joint) != namedJoints.end())
                            throw InputError(file_, place + ".attributes.JOINTS_" + std::to_string(s),
                                             "vertex " + std::to_string(v) + " names joint " + std::to_string(size_t(joint)) +
                                                 " twice with non-zero weights");
                        namedJoints.push_back(joint);
                        floatTotal += float(weight);
                        tolerance += 2e-7f;
                    }
                    // Every joint index names a joint of the skin, also where its weight is 0 (glTF 2.0).
                    if (joint >= double(joints))
                        throw InputError(file_, place + ".attributes.JOINTS_" + std::to_string(s),
                                         "vertex " + std::to_string(v) + " names joint " + std::to_string(size_t(joint)) +
                                             " of a skin with " + std::to_string(joints));
                    const size_t at = v * size_t(instance.influences) + s * 4 + size_t(k);
                    instance.skinJoints[at] = weight > 0 ? uint16_t(joint) : 0;
                    instance.skinWeights[at] = float(weight);
                    total += weight;
                }
            const size_t first = v * size_t(instance.influences);
            if (!(std::fabs(floatTotal - 1.0f) <= tolerance)) {
                if (weightsStated && !floatWeights)
                    throw InputError(file_, weightsPlace,
                                     "vertex " + std::to_string(v) + "'s weights sum to " + std::to_string(floatTotal) +
                                         ", not 1 (" + accessorNames + "; glTF requires normalized-integer weights to "
                                         "sum to 255 or 65535 before normalization)");
                if (repaired == 0) {
                    firstRepaired = v;
                    firstSum = lowest = highest = floatTotal;
                }
                lowest = std::min(lowest, floatTotal);
                highest = std::max(highest, floatTotal);
                ++repaired;
                if (total == 0) {
                    ++allZero;
                    instance.skinJoints[first] = uint16_t(jointSets[0](v, 0));  // within the skin: checked above
                    instance.skinWeights[first] = 1.0f;
                    continue;
                }
            }
            if (total > 0)
                for (int k = 0; k < instance.influences; ++k)
                    instance.skinWeights[first + size_t(k)] = float(instance.skinWeights[first + size_t(k)] / total);
        }
        if (repaired == 0) return;
        std::string what = std::to_string(repaired) + " of " + std::to_string(n) +
                           (repaired == 1 ? " vertices has weights" : " vertices have weights") +
                           " that do not sum to 1 (vertex " + std::to_string(firstRepaired) + "'s sum to " +
                           std::to_string(firstSum);
        if (repaired > 1) what += "; sums from " + std::to_string(lowest) + " to " + std::to_string(highest);
        what += ")";
        if (weightsStated && options_.strict)
            throw InputError(file_, weightsPlace, what + " (" + accessorNames +
                                                      "; glTF says weights should sum to 1; --strict refuses them)");
        // One warning for the weights, however many nodes and primitives use them; none for objects
        // the render does not read (checkUnusedObjects), which are refused above under --strict.
        if (readingUnusedObjects_ || !warnedWeights_.insert(weightAccessors).second) return;
        if (!weightsStated) what += "; a JOINTS_n or WEIGHTS_n accessor without data reads as zeros";
        std::string repair = "renormalised to sum 1";
        if (allZero == repaired) repair = "given weight 1 on their first joint, as their weights are all zero";
        else if (allZero > 0) repair += "; " + std::to_string(allZero) + " whose weights are all zero given weight 1 on their first joint";
        warnings_.add(file_ + ": " + weightsPlace + " (" + accessorNames + "): " + what + ": " + repair +
                      " (glTF says weights should sum to 1; --strict refuses them)");
    }

    void addMorphTargets(MeshInstance& instance, const tinygltf::Primitive& prim, const std::string& place,
                         const std::vector<double>& weights, bool hasNormals) {
        const size_t n = instance.vertexCount;
        for (size_t t = 0; t < prim.targets.size(); ++t) {
            const std::string targetPlace = place + "." + gltfPlace("targets", int(t));
            std::vector<Vec3f> dp(n, Vec3f(0.0f)), dn;
            auto pos = prim.targets[t].find("POSITION");
            if (pos != prim.targets[t].end()) {
                const AccessorData d = reader_.read(pos->second, targetPlace + ".POSITION", kPositionFormat);
                if (model_.accessors[size_t(pos->second)].minValues.size() != 3 ||
                    model_.accessors[size_t(pos->second)].maxValues.size() != 3)
                    throw InputError(file_, gltfPlace("accessors", pos->second),
                                     "is a morph target POSITION accessor without min and max (glTF requires both)");
                if (d.count != n)
                    throw InputError(file_, targetPlace + ".POSITION", "has " + std::to_string(d.count) +
                                                                          " elements for " + std::to_string(n) + " vertices");
                for (size_t v = 0; v < n; ++v) dp[v] = Vec3f(float(d(v, 0)), float(d(v, 1)), float(d(v, 2)));
            }
            auto nrm = prim.targets[t].find("NORMAL");
            if (hasNormals && nrm != prim.targets[t].end()) {
                const AccessorData d = reader_.read(nrm->second, targetPlace + ".NORMAL", kNormalFormat);
                if (d.count != n)
                    throw InputError(file_, targetPlace + ".NORMAL", "has " + std::to_string(d.count) +
                                                                        " elements for " + std::to_string(n) + " vertices");
                dn.resize(n);
                for (size_t v = 0; v < n; ++v) dn[v] = Vec3f(float(d(v, 0)), float(d(v, 1)), float(d(v, 2)));
            }
            instance.morphPositions.push_back(std::move(dp));
            instance.morphNormals.push_back(std::move(dn));
        }
        if (!prim.targets.empty()) {
            instance.morphRest = weights;
            instance.morphRest.resize(prim.targets.size(), 0.0);
            for (double w : instance.morphRest)
                if (!std::isfinite(w)) throw InputError(file_, place, "a morph target weight is not finite");
        }
    }

    void addCamera(Scene& scene, int n, const Transform& world) {
        const tinygltf::Node& node = model_.nodes[n];
        if (node.camera >= int(model_.cameras.size()))
            throw InputError(file_, gltfPlace("nodes", n) + ".camera", "refers to a camera that does not exist");
        scene.cameras.resize(model_.cameras.size());
        if (scene.cameras[node.camera]) return;  // the first node using a camera places it
        Camera lens = readLens(node.camera);
        lens.node = n;
        // glTF only asks for a positive field of view; a picture needs it below pi.
        if (lens.projection == Projection::Perspective && !(lens.yfov < 3.14159f))
            throw InputError(file_, gltfPlace("cameras", node.camera) + ".perspective.yfov",
                             "must lie below pi for the camera to render a picture");
        // World space here: Scene::finalize re-centres it with the lights.
        const Camera c = placeCamera(lens, world, Vec3d(0.0));
        if (!isFinite(c.position) || !hasDirection(c))
            throw InputError(file_, gltfPlace("nodes", n), "the camera node's transform is not finite or not invertible");
        scene.cameras[node.camera] = c;
        if (!scene.camera) scene.camera = c;
    }

    // glTF camera `index`'s lens, checked as glTF 2.0 (§5.12) requires.
    Camera readLens(int camera) const {
        const tinygltf::Camera& cam = model_.cameras[size_t(camera)];
        Camera lens;
        if (cam.type == "perspective") {
            lens.yfov = float(cam.perspective.yfov);
            lens.aspect = float(cam.perspective.aspectRatio);
            lens.znear = float(cam.perspective.znear);
            if (!(lens.yfov > 0) || !std::isfinite(lens.yfov))
                throw InputError(file_, gltfPlace("cameras", camera) + ".perspective.yfov", "must be positive");
        } else if (cam.type == "orthographic") {
            lens.projection = Projection::Orthographic;
            // The specification forbids zero magnifications and advises against negative ones.
            const double xmag = std::fabs(cam.orthographic.xmag), ymag = std::fabs(cam.orthographic.ymag);
            if (!(xmag > 0 && ymag > 0 && xmag < 1e30 && ymag < 1e30))
                throw InputError(file_, gltfPlace("cameras", camera) + ".orthographic",
                                 "xmag and ymag must be non-zero and finite");
            lens.ymag = float(ymag);
            lens.aspect = float(xmag / ymag);
            lens.znear = float(cam.orthographic.znear);
        } else {
            throw InputError(file_, gltfPlace("cameras", camera) + ".type",
                             "'" + cam.type + "' is not perspective or orthographic");
        }
        if (!(lens.znear >= 0) || !std::isfinite(lens.znear))
            throw InputError(file_, gltfPlace("cameras", camera), "znear must be non-negative and finite");
        // zfar: beyond znear (a perspective camera may omit it: infinite).
        const double zfar = cam.type == "perspective" ? cam.perspective.zfar : cam.orthographic.zfar;
        if ((cam.type == "orthographic" || zfar != 0) && !(zfar > lens.znear))
            throw InputError(file_, gltfPlace("cameras", camera) + "." + cam.type + ".zfar",
                             "must lie beyond znear (" + std::to_string(lens.znear) + ")");
        return lens;
    }

    void addLight(Scene& scene, int n, const Transform& world, const tinygltf::Value& ref) {
        const std::string place = gltfPlace("nodes", n) + ".extensions.KHR_lights_punctual.light";
        if (!ref.IsNumber()) throw InputError(file_, place, "must be a light index");
        const int index = ref.GetNumberAsInt();
        if (index < 0 || index >= int(model_.lights.size()))
            throw InputError(file_, place, "refers to light " + std::to_string(index) + ", which does not exist");
        if (!readingUnusedObjects_) usedLights_.insert(index);
        const tinygltf::Light& l = model_.lights[index];
        PunctualLight out;
        out.name = l.name.empty() ? "light " + std::to_string(index) : l.name;
        out.node = n;
        const Vec3f colour = vec3FromFactor(l.color, Vec3f(1.0f));
        if (!isFinite(colour) || colour.x < 0 || colour.y < 0 || colour.z < 0 || maxComponent(colour) > 1)
            throw InputError(file_, gltfPlace("KHR_lights_punctual.lights", index) + ".color",
                             "must lie in [0, 1] (KHR_lights_punctual: the strength is in intensity)");
        out.intensity = colour * float(l.intensity);
        placeLight(out, world, Vec3d(0.0));  // world space; Scene::finalize re-centres it
        if (l.type == "point") out.type = LightType::Point;
        else if (l.type == "spot") {
            out.type = LightType::Spot;
            const double outer = l.spot.outerConeAngle;
            if (!(outer > 0 && outer <= M_PI / 2 + 1e-9))
                throw InputError(file_, gltfPlace("KHR_lights_punctual.lights", index) + ".spot.outerConeAngle", "must lie in (0, pi/2]");
            const double inner = l.spot.innerConeAngle;
            if (!(inner >= 0 && inner < outer))
                throw InputError(file_, gltfPlace("KHR_lights_punctual.lights", index) + ".spot.innerConeAngle",
                                 "must lie in [0, outerConeAngle)");
            out.cosOuterCone = float(std::cos(outer));
        } else if (l.type == "directional") out.type = LightType::Directional;
        else throw InputError(file_, gltfPlace("KHR_lights_punctual.lights", index) + ".type", "unknown light type '" + l.type + "'");
        if (!isFinite(out.intensity) || out.intensity.x < 0 || out.intensity.y < 0 || out.intensity.z < 0 ||
            !isFinite(out.position) || dot(out.direction, out.direction) == 0)
            throw InputError(file_, gltfPlace("KHR_lights_punctual.lights", index), "colour and intensity must be finite and non-negative");
        scene.lights.push_back(out);
    }

    const GltfDocument& document_;
    const tinygltf::Model& model_;
    const std::vector<GltfFinding>& findings_;
    const std::string& file_;
    Warnings& warnings_;
    GltfReadOptions options_;
    AccessorReader reader_;
    std::map<int, int> skinOf_;  // glTF skin -> Scene::skins
    std::set<int> usedMeshes_, usedMaterials_, usedLights_;
    std::set<int> decodedImages_;  // the images materials' textures decoded (convertMaterial)
    TextureImages images_{document_, reader_};
    std::map<int, Texture> textures_;  // the base colour and emissive textures that could be read, by texture index
    std::set<std::vector<int>> warnedWeights_;  // the WEIGHTS_n accessors already warned about (addInfluences)
    bool readingUnusedObjects_ = false;         // within checkUnusedObjects
    uint32_t defaultMaterial_ = 0;
};

}  // namespace

namespace {

Scene buildScene(const GltfDocument& document, const std::string& path, Warnings& warnings, const GltfReadOptions& options) {
    const tinygltf::Model& model = document.model;
    for (const auto& ext : model.extensionsRequired) {
        // glTF 2.0 (§3.12): every required extension is also listed as used.
        if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), ext) == model.extensionsUsed.end())
            throw InputError(path, "extensionsRequired", ext + " is required but not listed in extensionsUsed");
        if (!kSupportedExtensions.count(ext))
            throw InputError(path, "extensionsRequired", "requires extension " + ext + ", which qsgi does not implement");
    }
    for (const auto& ext : model.extensionsUsed)
        if (!kSupportedExtensions.count(ext)) warnings.add(path + ": extension " + ext + " is ignored");

    return SceneBuilder(document, path, warnings, options).build();
}

}  // namespace

Scene loadGltfScene(const std::string& path, Warnings& warnings, const GltfReadOptions& options) {
    return buildScene(readGltfDocument(path, warnings), path, warnings, options);
}

Scene loadGltfScene(const GltfDocument& document, const std::string& path, Warnings& warnings, const GltfReadOptions& options) {
    return buildScene(document, path, warnings, options);
}

Scene loadGltfSceneFromMemory(const std::string& path, std::string bytes, const std::string& baseDir,
                              Warnings& warnings, const GltfReadOptions& options) {
    return buildScene(parseGltfDocument(path, std::move(bytes), baseDir, warnings), path, warnings, options);
}

}  // namespace qsgi
