#include "output/baked_asset.h"

#include "scene/gltf_accessor.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <set>
#include <filesystem>

namespace qsgi {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;
// A GLB's length is a uint32 (glTF 2.0 §4.4.3.1).
constexpr uint64_t kMaxGlbBytes = 0xFFFFFFFFull;
const char* const kOption = "gltf_out (--gltf-out)";

std::string colourName(int set) { return "COLOR_" + std::to_string(set); }

// The binary chunk and the JSON's bufferViews and accessors into it.
class BinaryBuilder {
public:
    explicit BinaryBuilder(json& doc) : doc_(doc) {
        if (!doc_.contains("bufferViews")) doc_["bufferViews"] = json::array();
        if (!doc_.contains("accessors")) doc_["accessors"] = json::array();
    }
    std::string& bytes() { return bin_; }
    void align(size_t to) { bin_.resize((bin_.size() + to - 1) / to * to, '\0'); }

    // `target` 34962 (ARRAY_BUFFER) for vertex attributes' views, 0 for others (sparse parts,
    // animation keys, images), which glTF leaves without one.
    int addView(const void* data, size_t size, int target = 0) {
        align(4);
        json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", size}};
        if (target) view["target"] = target;
        bin_.append(static_cast<const char*>(data), size);
        doc_["bufferViews"].push_back(std::move(view));
        return int(doc_["bufferViews"].size()) - 1;
    }
    int addAccessor(json accessor) {
        doc_["accessors"].push_back(std::move(accessor));
        return int(doc_["accessors"].size()) - 1;
    }
    int addVec3(const Vec3f* values, size_t count) {
        return addAccessor({{"bufferView", addView(values, count * sizeof(Vec3f), kArrayBuffer)}, {"componentType", kFloat},
                            {"count", count}, {"type", "VEC3"}});
    }
    // Zeros without a view (glTF 2.0 §3.6.2.3: an accessor without bufferView reads as zeros).
    // `bounds`: with min and max 0, which glTF requires of a morph target's POSITION (§3.7.2.2).
    int addZeroVec3(size_t count, bool bounds = false) {
        json accessor = {{"componentType", kFloat}, {"count", count}, {"type", "VEC3"}};
        if (bounds) {
            accessor["min"] = {0, 0, 0};
            accessor["max"] = {0, 0, 0};
        }
        return addAccessor(std::move(accessor));
    }
    // Zeros but at `indices` (strictly increasing), which hold `values`.
    int addSparseVec3(size_t count, const std::vector<uint32_t>& indices, const std::vector<Vec3f>& values, int indexView) {
        json accessor = {{"componentType", kFloat}, {"count", count}, {"type", "VEC3"}};
        if (!indices.empty())
            accessor["sparse"] = {{"count", indices.size()},
                                  {"indices", {{"bufferView", indexView}, {"componentType", kUnsignedInt}}},
                                  {"values", {{"bufferView", addView(values.data(), values.size() * sizeof(Vec3f))}}}};
        return addAccessor(std::move(accessor));
    }
    int addScalars(const std::vector<float>& values, bool bounds) {
        json accessor = {{"bufferView", addView(values.data(), values.size() * sizeof(float))}, {"componentType", kFloat},
                         {"count", values.size()}, {"type", "SCALAR"}};
        if (bounds && !values.empty()) {
            accessor["min"] = {*std::min_element(values.begin(), values.end())};
            accessor["max"] = {*std::max_element(values.begin(), values.end())};
        }
        return addAccessor(std::move(accessor));
    }
    int addFloats(const std::vector<float>& values, const char* type, size_t count) {
        return addAccessor({{"bufferView", addView(values.data(), values.size() * sizeof(float))}, {"componentType", kFloat},
                            {"count", count}, {"type", type}});
    }

private:
    json& doc_;
    std::string bin_;
};

// Whether instance a's bake in frame x equals instance b's in frame y, bit for bit.
bool sameBake(const BakedFrame& x, const MeshInstance& a, const BakedFrame& y, const MeshInstance& b) {
    if (a.vertexCount != b.vertexCount) return false;
    const size_t bytes = size_t(a.vertexCount) * sizeof(Vec3f);
    return std::memcmp(&x.radiance[a.firstVertex], &y.radiance[b.firstVertex], bytes) == 0 &&
           std::memcmp(&x.irradiance[a.firstVertex], &y.irradiance[b.firstVertex], bytes) == 0;
}

// The rendered nodes of one glTF mesh, each with its instances by primitive (nullptr: skipped).
struct MeshUse {
    std::vector<int> nodes;
    std::map<int, std::vector<const MeshInstance*>> instances;  // node → by primitive
};

size_t primitiveCount(const json& doc, int mesh) { return doc["meshes"][size_t(mesh)]["primitives"].size(); }

// A primitive's vertex count, from its POSITION or else any attribute whose accessor exists (0:
// none tells it).
size_t vertexCountOf(const json& doc, const json& primitive) {
    if (!primitive.contains("attributes") || !primitive["attributes"].is_object() || !doc.contains("accessors")) return 0;
    const json& attributes = primitive["attributes"];
    const json& accessors = doc["accessors"];
    auto countOf = [&](const json& index) -> size_t {
        if (!index.is_number_unsigned() || index.get<size_t>() >= accessors.size()) return 0;
        const json& a = accessors[index.get<size_t>()];
        return a.contains("count") && a["count"].is_number_unsigned() ? a["count"].get<size_t>() : 0;
    };
    if (attributes.contains("POSITION") && countOf(attributes["POSITION"]) > 0) return countOf(attributes["POSITION"]);
    for (const auto& [name, index] : attributes.items())
        if (countOf(index) > 0) return countOf(index);
    return 0;
}

size_t targetCount(const json& mesh) {
    const json& p0 = mesh["primitives"][0];
    return p0.contains("targets") ? p0["targets"].size() : 0;
}

// The input's buffers, images and views moved into one buffer: every bufferView's buffer becomes
// 0 at its buffer's offset; an image's uri becomes a view of its file's bytes.
void packBuffers(const GltfDocument& document, json& doc, BinaryBuilder& bin, Warnings& warnings, const std::string& file,
                 const std::string& assetFolder) {
    const tinygltf::Model& model = document.model;
    std::vector<size_t> start(model.buffers.size(), 0);
    for (size_t b = 0; b < model.buffers.size(); ++b) {
        bin.align(16);  // keeps every accessor's alignment within its buffer
        start[b] = bin.bytes().size();
        if (!document.absentBuffers.count(int(b))) {
            bin.bytes().append(reinterpret_cast<const char*>(model.buffers[b].data.data()), model.buffers[b].data.size());
        } else {
            // No data (no uri): nothing reads it, but its views must stay inside the one buffer.
            const size_t length = doc["buffers"][b].value("byteLength", size_t(0));
            if (length > kMaxGlbBytes) throw InputError(file, "buffers[" + std::to_string(b) + "].byteLength", "is beyond what a GLB holds");
            bin.bytes().append(length, '\0');
            warnings.add(file + ": buffers[" + std::to_string(b) + "] has no data; the asset holds zeros in its place");
        }
    }
    if (doc.contains("bufferViews"))
        for (json& view : doc["bufferViews"]) {
            const size_t b = view.value("buffer", size_t(0));
            view["buffer"] = 0;
            view["byteOffset"] = view.value("byteOffset", size_t(0)) + (b < start.size() ? start[b] : 0);
        }
    if (doc.contains("images"))
        for (size_t i = 0; i < doc["images"].size() && i < model.images.size(); ++i) {
            json& image = doc["images"][i];
            if (!image.contains("uri")) continue;
            const tinygltf::Image& decoded = model.images[i];
            const std::string uri = image["uri"].is_string() ? image["uri"].get<std::string>() : "";
            // The format the bytes are (not the name's extension, which may lie).
            const std::vector<unsigned char>& b = decoded.image;
            auto startsWith = [&](const char* magic, size_t at = 0) {
                const size_t n = std::strlen(magic);
                return b.size() >= at + n && std::memcmp(b.data() + at, magic, n) == 0;
            };
            const std::string mime = startsWith("\x89PNG") ? "image/png" : startsWith("\xFF\xD8\xFF") ? "image/jpeg"
                                   : startsWith("RIFF") && startsWith("WEBP", 8) ? "image/webp"
                                   : startsWith("\xABKTX 20\xBB") ? "image/ktx2" : "";
            if (mime.empty()) {
                // Left where it is: the uri made to reach the file from the asset's folder.
                const fs::path target = fs::path(document.baseDir) / uri;
                if (!uri.empty() && uri.rfind("data:", 0) != 0 && !assetFolder.empty())
                    image["uri"] = fs::relative(fs::absolute(target), fs::absolute(assetFolder)).generic_string();
                warnings.add(file + ": images[" + std::to_string(i) + "] ('" + uri.substr(0, 200) +
                             "') is no PNG, JPEG, WebP or KTX2 file qsgi could read, so it is not embedded; asset.glb refers to it");
                continue;
            }
            image.erase("uri");
            image["bufferView"] = bin.addView(decoded.image.data(), decoded.image.size());
            image["mimeType"] = mime;
        }
}

// A node's local transform as its JSON gives it (glTF 2.0 §5.25: a matrix, or T·R·S).
Transform nodeTransform(const json& node) {
    if (node.contains("matrix")) {
        const std::vector<double> m = node["matrix"].get<std::vector<double>>();
        return Transform::fromColumnMajor(m.data());
    }
    const std::vector<double> t = node.value("translation", std::vector<double>{0, 0, 0});
    const std::vector<double> r = node.value("rotation", std::vector<double>{0, 0, 0, 1});
    const std::vector<double> s = node.value("scale", std::vector<double>{1, 1, 1});
    return Transform::fromTRS(Vec3d(t[0], t[1], t[2]), {r[0], r[1], r[2], r[3]}, Vec3d(s[0], s[1], s[2]));
}

// Gives the node translation, rotation and scale (instead of a matrix, which glTF does not animate).
void setNodeTrs(json& node, const NodeTrs& trs) {
    node.erase("matrix");
    node["translation"] = {trs.translation.x, trs.translation.y, trs.translation.z};
    node["rotation"] = {trs.rotation[0], trs.rotation[1], trs.rotation[2], trs.rotation[3]};
    node["scale"] = {trs.scale.x, trs.scale.y, trs.scale.z};
}

// glTF's weights of a node at rest: its own, else its mesh's, else zeros.
std::vector<double> restWeights(const json& node, const json& mesh, size_t count) {
    std::vector<double> w(count, 0.0);
    const json* given = node.contains("weights") ? &node["weights"] : mesh.contains("weights") ? &mesh["weights"] : nullptr;
    if (given)
        for (size_t i = 0; i < count && i < given->size(); ++i) w[i] = (*given)[i].get<double>();
    return w;
}

const char* interpolationKeyword(Interpolation i) {
    return i == Interpolation::Step ? "STEP" : i == Interpolation::Linear ? "LINEAR" : "CUBICSPLINE";
}

// The track of animation `a`'s channel driving node `node`'s weights, as the scene read it.
const KeyframeTrack* weightsTrack(const Scene& scene, size_t a, int node) {
    if (a >= scene.animations.size()) return nullptr;
    for (const AnimationChannel& c : scene.animations[a].channels)
        if (c.node == node && c.property == AnimatedProperty::Weights) return &c.track;
    return nullptr;
}

// The lighting weights channels (and a transform file's motion) in the animation that played, or
// in a new one; every other animation's weights channels on those nodes extended with zeros.
void addLightingAnimation(json& doc, BinaryBuilder& bin, const Scene& scene, const std::vector<double>& frameSeconds,
                          const std::map<int, size_t>& ownTargets,
                          const std::map<int, int>& nodeMesh, const std::vector<NodeMotion>& motion,
                          const BakedAssetSettings& settings, Warnings& warnings, const std::string& file) {
    if (!doc.contains("animations")) doc["animations"] = json::array();
    json& animations = doc["animations"];
    const size_t fileAnimations = animations.size();
    size_t played = size_t(settings.playedAnimation);
    if (settings.playedAnimation < 0 || !motion.empty() || played >= fileAnimations) {
        animations.push_back({{"name", "qsgi"}, {"channels", json::array()}, {"samplers", json::array()}});
        played = animations.size() - 1;
    }
    // Key times are floats in the file: the frames' as floats, strictly increasing.
    std::vector<float> frameTimes;
    for (const double t : frameSeconds) frameTimes.push_back(float(t));
    const size_t frames = frameTimes.size(), lighting = frames - 1;
    int frameTimesAccessor = -1;
    auto frameTimesIndex = [&] {
        if (frameTimesAccessor < 0) frameTimesAccessor = bin.addScalars(frameTimes, true);
        return frameTimesAccessor;
    };
    auto addSampler = [&](json& animation, int input, int output, Interpolation interpolation) {
        animation["samplers"].push_back({{"input", input}, {"output", output}, {"interpolation", interpolationKeyword(interpolation)}});
        return int(animation["samplers"].size()) - 1;
    };
    // Which frame shows at time t: the last whose time is at or before t (the first before them all).
    auto frameAtTime = [&](float t) {
        const size_t after = size_t(std::upper_bound(frameTimes.begin(), frameTimes.end(), t) - frameTimes.begin());
        return after == 0 ? size_t(0) : after - 1;
    };

    for (const NodeMotion& m : motion) {
        json& node = doc["nodes"][size_t(m.node)];
        if (node.contains("matrix")) setNodeTrs(node, m.frames.front());
        std::vector<float> translation, rotation, scale;
        for (const NodeTrs& trs : m.frames) {
            for (int c = 0; c < 3; ++c) translation.push_back(float(trs.translation[c]));
            for (int c = 0; c < 4; ++c) rotation.push_back(float(trs.rotation[size_t(c)]));
            for (int c = 0; c < 3; ++c) scale.push_back(float(trs.scale[c]));
        }
        json& animation = animations[played];
        const std::pair<const char*, std::pair<const std::vector<float>*, const char*>> paths[] = {
            {"translation", {&translation, "VEC3"}}, {"rotation", {&rotation, "VEC4"}}, {"scale", {&scale, "VEC3"}}};
        for (const auto& [path, data] : paths) {
            const int sampler = addSampler(animation, frameTimesIndex(), bin.addFloats(*data.first, data.second, frames), Interpolation::Linear);
            animation["channels"].push_back({{"sampler", sampler}, {"target", {{"node", m.node}, {"path", path}}}});
        }
    }

    // An output of animation weights: sparse where most of it is 0 (the one-hot lighting part of
    // many frames would otherwise grow with the square of the frame count).
    auto addWeights = [&](const std::vector<float>& values) {
        std::vector<uint32_t> indices;
        std::vector<float> nonzero;
        for (size_t i = 0; i < values.size(); ++i)
            if (values[i] != 0.0f) {
                indices.push_back(uint32_t(i));
                nonzero.push_back(values[i]);
            }
        if (indices.size() * 2 >= values.size()) return bin.addFloats(values, "SCALAR", values.size());
        json accessor = {{"componentType", kFloat}, {"count", values.size()}, {"type", "SCALAR"}};
        if (!indices.empty())
            accessor["sparse"] = {{"count", indices.size()},
                                  {"indices", {{"bufferView", bin.addView(indices.data(), indices.size() * 4)}, {"componentType", kUnsignedInt}}},
                                  {"values", {{"bufferView", bin.addView(nonzero.data(), nonzero.size() * 4)}}}};
        return bin.addAccessor(std::move(accessor));
    };
    auto oneHot = [&](size_t frame, std::vector<float>& values) {
        for (size_t i = 0; i < lighting; ++i) values.push_back(frame == i + 1 ? 1.0f : 0.0f);
    };
    for (const auto& [node, mesh] : nodeMesh) {
        const size_t own = ownTargets.at(mesh);
        const std::vector<double> rest = restWeights(doc["nodes"][size_t(node)], doc["meshes"][size_t(mesh)], own);
        // The animation that shows this node's lighting: the one played, or with all played at
        // once, the one already driving its weights (two channels on them would fight).
        size_t home = played;
        if (settings.playedAll)
            for (size_t a = 0; a < fileAnimations; ++a)
                if (animations[a].contains("channels"))
                    for (const json& c : animations[a]["channels"])
                        if (c.contains("target") && c["target"].value("node", -1) == node && c["target"].value("path", "") == "weights") home = a;
        bool drivenInHome = false;
        for (size_t a = 0; a < animations.size(); ++a) {
            json& animation = animations[a];
            if (!animation.contains("channels")) continue;
            for (json& channel : animation["channels"]) {
                if (!channel.contains("target") || channel["target"].value("node", -1) != node ||
                    channel["target"].value("path", "") != "weights")
                    continue;
                const json& sampler = animation["samplers"][channel["sampler"].get<size_t>()];
                const KeyframeTrack* track = weightsTrack(scene, a, node);
                KeyframeTrack zeros;  // a channel the loader did not keep (its data all zeros by default)
                if (!track) {
                    zeros.interpolation = sampler.value("interpolation", "LINEAR") == "STEP" ? Interpolation::Step
                                        : sampler.value("interpolation", "LINEAR") == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                                                                   : Interpolation::Linear;
                    zeros.components = int(own);
                    const json& input = doc["accessors"][sampler["input"].get<size_t>()];
                    zeros.times.assign(input.value("count", size_t(1)), 0.0);
                    for (size_t k = 0; k < zeros.times.size(); ++k) zeros.times[k] = double(k);  // placeholders: only their count is used
                    zeros.values.assign(zeros.times.size() * own * (zeros.interpolation == Interpolation::CubicSpline ? 3 : 1), 0.0);
                    track = &zeros;
                }
                std::vector<float> keys(track->times.begin(), track->times.end());
                std::vector<float> values;
                Interpolation interpolation = track->interpolation;
                int input = sampler["input"].get<int>();
                if (a != home || track == &zeros) {
                    // Our targets stay at 0 while it plays (the first frame's lighting).
                    const size_t groups = interpolation == Interpolation::CubicSpline ? 3 : 1;
                    for (size_t k = 0; k < keys.size(); ++k)
                        for (size_t g = 0; g < groups; ++g) {
                            for (size_t i = 0; i < own; ++i) values.push_back(float(track->values[(k * groups + g) * own + i]));
                            values.insert(values.end(), lighting, 0.0f);
                        }
                    if (a == home) continue;  // replaced below by the lighting's own channel
                } else {
                    // Its keys and the frames' merged. A cubic spline is resampled LINEAR there
                    // (exact at the keys); a LINEAR sampler gains a key just before each frame so
                    // that the lighting steps rather than fades.
                    drivenInHome = true;
                    if (interpolation == Interpolation::CubicSpline) {
                        warnings.add(file + ": animations[" + std::to_string(a) + "]'s cubic-spline weights on nodes[" +
                                     std::to_string(node) + "] are written LINEAR between their keys and the frames");
                        interpolation = Interpolation::Linear;
                    }
                    keys.insert(keys.end(), frameTimes.begin(), frameTimes.end());
                    if (interpolation == Interpolation::Linear)
                        for (size_t k = 1; k < frames; ++k) {
                            const float before = frameTimes[k] - 1e-3f * (frameTimes[k] - frameTimes[k - 1]);
                            if (before > frameTimes[k - 1] && before < frameTimes[k]) keys.push_back(before);
                        }
                    std::sort(keys.begin(), keys.end());
                    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
                    std::vector<double> sampled(std::max<size_t>(own, 1));
                    for (const float t : keys) {
                        track->sample(double(t), false, sampled.data());
                        for (size_t i = 0; i < own; ++i) values.push_back(float(sampled[i]));
                        oneHot(frameAtTime(t), values);
                    }
                    input = bin.addScalars(keys, true);
                }
                channel["sampler"] = addSampler(animation, input, addWeights(values), interpolation);
            }
        }
        if (!drivenInHome) {
            // A channel of its own, or (a channel the loader did not keep, in its animation) in
            // place of that one: the node's weights are driven once an animation.
            std::vector<float> values;
            for (size_t f = 0; f < frames; ++f) {
                for (size_t i = 0; i < own; ++i) values.push_back(float(rest[i]));
                oneHot(f, values);
            }
            json& animation = animations[home];
            const int sampler = addSampler(animation, frameTimesIndex(), addWeights(values), Interpolation::Step);
            bool replaced = false;
            for (json& c : animation["channels"])
                if (c.contains("target") && c["target"].value("node", -1) == node && c["target"].value("path", "") == "weights") {
                    c["sampler"] = sampler;
                    replaced = true;
                }
            if (!replaced) animation["channels"].push_back({{"sampler", sampler}, {"target", {{"node", node}, {"path", "weights"}}}});
        }
    }
    // glTF forbids an animation without channels, and an empty list of them.
    if (animations.size() > fileAnimations && animations.back()["channels"].empty()) animations.erase(animations.size() - 1);
    if (animations.empty()) doc.erase("animations");
}

// glTF's element type names as tinygltf numbers them.
int elementType(const std::string& type) {
    return type == "SCALAR" ? TINYGLTF_TYPE_SCALAR : type == "VEC2" ? TINYGLTF_TYPE_VEC2 : type == "VEC3" ? TINYGLTF_TYPE_VEC3
         : type == "VEC4" ? TINYGLTF_TYPE_VEC4 : -1;
}

// A primitive as --subdivide refined it (MeshInstance::refinedFrom): every attribute and morph
// target the file gives, its own vertices as they are and each new vertex the mean of its edge's
// two (normals renormalised, a tangent's handedness its first corner's), written as floats; the
// skin's joints and weights as the refinement blended them; the refined triangles as indices.
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

}  // namespace

void checkAssetTakesBake(const GltfDocument& document, const Scene& scene, const BakedAssetSettings& settings,
                         const std::string& sceneFile) {
    const json& doc = document.json;
    if (doc.contains("extensionsUsed") && doc["extensionsUsed"].is_array())
        for (const json& e : doc["extensionsUsed"])
            if (e == "EXT_meshopt_compression")
                throw InputError(sceneFile, "extensionsUsed", "has EXT_meshopt_compression, whose buffers --gltf-out cannot repack");
    std::set<int> meshes;
    for (const MeshInstance& instance : scene.instances) {
        if (instance.mesh < 0) throw InputError(kOption, "", "needs a scene read from a glTF file");
        meshes.insert(instance.mesh);
        const json& primitive = doc["meshes"][size_t(instance.mesh)]["primitives"][size_t(instance.primitive)];
        const std::string place = "meshes[" + std::to_string(instance.mesh) + "].primitives[" + std::to_string(instance.primitive) + "]";
        if (instance.vertexCount - instance.refinedFrom.size() != vertexCountOf(doc, primitive))
            throw InputError(sceneFile, place, "does not hold the vertices the scene was read with");
        const json& attributes = primitive["attributes"];
        if (settings.colourSet >= 0) {
            if (attributes.contains(colourName(settings.colourSet)))
                throw InputError(sceneFile, place + ".attributes." + colourName(settings.colourSet),
                                 "is the asset's own: --gltf-colour never overwrites a colour set; give the next free one");
            if (settings.colourSet > 0 && !attributes.contains(colourName(settings.colourSet - 1)))
                throw InputError(sceneFile, place + ".attributes",
                                 "has no " + colourName(settings.colourSet - 1) + ", so --gltf-colour " +
                                     std::to_string(settings.colourSet) + " would leave a gap (glTF numbers colour sets from 0 without gaps)");
        }
    }
    // Every primitive of a baked mesh, rendered or not, may gain the two attributes.
    for (const int mesh : meshes) {
        const json& primitives = doc["meshes"][size_t(mesh)]["primitives"];
        for (size_t p = 0; p < primitives.size(); ++p)
            for (const char* name : {"_RADIANCE", "_IRRADIANCE"})
                if (primitives[p].contains("attributes") && primitives[p]["attributes"].contains(name))
                    throw InputError(sceneFile, "meshes[" + std::to_string(mesh) + "].primitives[" + std::to_string(p) + "].attributes." + name,
                                     "is already there (a baked asset?): --gltf-out adds it, so bake the original asset");
    }
}

std::string encodeBakedAsset(const GltfDocument& document, const Scene& scene, size_t frameCount,
                             const std::function<BakedFrame(size_t)>& frameAt, const std::vector<NodeMotion>& motion,
                             const BakedAssetSettings& settings, Warnings& warnings, BakedAssetSummary* summary) {
    const std::string file = scene.sourcePath;
    json doc = document.json;
    BinaryBuilder bin(doc);
    packBuffers(document, doc, bin, warnings, file, settings.assetFolder);
    const size_t assetBytes = bin.bytes().size();

    // Which nodes show which glTF mesh, in the order the scene placed them.
    std::map<int, MeshUse> uses;
    for (const MeshInstance& instance : scene.instances) {
        MeshUse& use = uses[instance.mesh];
        auto& list = use.instances[instance.node];
        if (list.empty()) {
            use.nodes.push_back(instance.node);
            list.resize(primitiveCount(doc, instance.mesh), nullptr);
        }
        list[size_t(instance.primitive)] = &instance;
    }

    // Pass 1: the nodes of a mesh fall into groups whose bakes are equal in every frame (split on
    // the first frame that tells them apart), and a group is animated if any frame differs from
    // frame 0 for it.
    struct Group {
        int mesh = -1;  // the output mesh: the input's for the first group, a copy for the others
        std::vector<int> nodes;
        bool animated = false;
    };
    std::map<int, std::vector<Group>> groups;
    for (const auto& [mesh, use] : uses) groups[mesh].push_back(Group{mesh, use.nodes, false});
    const BakedFrame first = frameAt(0);
    std::vector<double> times(frameCount);
    auto instancesOf = [&](int mesh, int node) -> const std::vector<const MeshInstance*>& { return uses.at(mesh).instances.at(node); };
    for (size_t k = 0; k < frameCount; ++k) {
        const BakedFrame frame = k == 0 ? first : frameAt(k);
        times[k] = frame.seconds;
        for (auto& [mesh, list] : groups) {
            std::vector<Group> split;
            for (const Group& g : list) {
                const size_t begin = split.size();
                for (const int node : g.nodes) {
                    auto same = [&](const Group& other) {
                        const auto& a = instancesOf(mesh, node);
                        const auto& b = instancesOf(mesh, other.nodes[0]);
                        for (size_t p = 0; p < a.size(); ++p) {
                            if (!a[p] != !b[p]) return false;
                            if (a[p] && (a[p]->refinedFrom != b[p]->refinedFrom || !sameBake(frame, *a[p], frame, *b[p]))) return false;
                        }
                        return true;
                    };
                    auto match = std::find_if(split.begin() + std::ptrdiff_t(begin), split.end(), same);
                    if (match == split.end()) split.push_back(Group{-1, {node}, g.animated});
                    else match->nodes.push_back(node);
                }
            }
            for (Group& g : split) {
                if (g.animated || k == 0) continue;
                for (const MeshInstance* instance : instancesOf(mesh, g.nodes[0]))
                    if (instance && !sameBake(frame, *instance, first, *instance)) g.animated = true;
            }
            list = std::move(split);
        }
    }
    // A primitive without a vertex count (no attribute with an accessor) cannot take the targets
    // every primitive of a morphing mesh must have: its mesh keeps frame 0's lighting.
    for (auto& [mesh, list] : groups)
        for (Group& g : list) {
            if (!g.animated) continue;
            const auto& instances = instancesOf(mesh, g.nodes[0]);
            for (size_t p = 0; p < instances.size(); ++p)
                if (!instances[p] && vertexCountOf(doc, doc["meshes"][size_t(mesh)]["primitives"][p]) == 0) {
                    g.animated = false;
                    warnings.add(file + ": meshes[" + std::to_string(mesh) + "].primitives[" + std::to_string(p) +
                                 "] has no vertices to give morph targets, so the mesh shows only the first frame's lighting");
                }
        }
    // The first group keeps the mesh; the others get copies, their nodes pointed at them.
    size_t copies = 0;
    for (auto& [mesh, list] : groups)
        for (size_t g = 0; g < list.size(); ++g) {
            if (g == 0) {
                list[g].mesh = mesh;
                continue;
            }
            json copy = doc["meshes"][size_t(mesh)];
            doc["meshes"].push_back(std::move(copy));
            list[g].mesh = int(doc["meshes"].size()) - 1;
            for (const int node : list[g].nodes) doc["nodes"][size_t(node)]["mesh"] = list[g].mesh;
            ++copies;
        }

    // Pass 2: frame 0's values as attributes, later frames' differences as sparse targets.
    const bool colour = settings.colourSet >= 0;
    auto colourOf = [&](const Vec3f& radiance) {
        Vec3f c;
        for (int i = 0; i < 3; ++i) c[i] = float(std::clamp(double(radiance[i]) * settings.exposure, 0.0, 1.0));
        return c;
    };
    struct Target {
        int radiance, irradiance, colour, position;  // accessors (-1: none)
    };
    std::map<std::pair<int, size_t>, std::vector<Target>> targets;  // (output mesh, primitive) → per later frame
    // Every target added holds a POSITION of zeros (issue 46): Blender's importer makes shape keys
    // only of targets with POSITION, and fails on a weights channel whose targets gave it none.
    // Without a view they take no bytes, and the targets of one vertex count share one accessor.
    // A primitive without POSITION gets none (glTF forbids a target attribute its primitive lacks).
    std::map<size_t, int> zeroPositions;  // vertex count → accessor
    auto zeroPositionsOf = [&](const json& primitive, size_t count) {
        if (!primitive.contains("attributes") || !primitive["attributes"].contains("POSITION")) return -1;
        const auto [at, added] = zeroPositions.try_emplace(count, -1);
        if (added) at->second = bin.addZeroVec3(count, true);
        return at->second;
    };
    size_t animatedPrimitives = 0;
    const AccessorReader reader(document, file);
    const bool anyAnimated = std::any_of(groups.begin(), groups.end(), [](const auto& entry) {
        return std::any_of(entry.second.begin(), entry.second.end(), [](const Group& g) { return g.animated; });
    });
    for (size_t k = 0; k < (anyAnimated ? frameCount : 1); ++k) {
        const BakedFrame frame = k == 0 ? first : frameAt(k);
        for (const auto& [mesh, list] : groups)
            for (const Group& g : list) {
                if (k > 0 && !g.animated) continue;
                json& out = doc["meshes"][size_t(g.mesh)];
                const auto& instances = instancesOf(mesh, g.nodes[0]);
                for (size_t p = 0; p < instances.size(); ++p) {
                    const MeshInstance* instance = instances[p];
                    json& primitive = out["primitives"][p];
                    const size_t count = instance ? instance->vertexCount : vertexCountOf(doc, primitive);
                    if (k == 0 && instance && !instance->refinedFrom.empty())
                        primitive = refinedPrimitive(primitive, doc, bin, reader, scene, *instance,
                                                     "meshes[" + std::to_string(mesh) + "].primitives[" + std::to_string(p) + "]");
                    if (k == 0) {
                        json& attributes = primitive["attributes"];
                        if (!instance) {
                            // Not rendered (points, lines): no bake, but where the mesh gains
                            // targets, zeros, as every primitive of a morphing mesh has the targets'
                            // attributes; never a colour set (it would paint its own over).
                            if (g.animated) {
                                attributes["_RADIANCE"] = bin.addZeroVec3(count);
                                attributes["_IRRADIANCE"] = bin.addZeroVec3(count);
                            }
                            continue;
                        }
                        attributes["_RADIANCE"] = bin.addVec3(&frame.radiance[instance->firstVertex], count);
                        attributes["_IRRADIANCE"] = bin.addVec3(&frame.irradiance[instance->firstVertex], count);
                        if (colour) {
                            std::vector<Vec3f> c(count);
                            for (size_t v = 0; v < count; ++v) c[v] = colourOf(frame.radiance[instance->firstVertex + v]);
                            attributes[colourName(settings.colourSet)] = bin.addVec3(c.data(), count);
                        }
                        if (g.animated) ++animatedPrimitives;
                        continue;
                    }
                    Target target{-1, -1, -1, zeroPositionsOf(primitive, count)};
                    if (!instance) {
                        target.radiance = bin.addZeroVec3(count);
                        target.irradiance = bin.addZeroVec3(count);
                    } else {
                        std::vector<uint32_t> changed;
                        std::vector<Vec3f> dRadiance, dIrradiance, dColour;
                        for (size_t v = 0; v < count; ++v) {
                            const size_t i = instance->firstVertex + v;
                            if (frame.radiance[i] == first.radiance[i] && frame.irradiance[i] == first.irradiance[i]) continue;
                            changed.push_back(uint32_t(v));
                            dRadiance.push_back(frame.radiance[i] - first.radiance[i]);
                            dIrradiance.push_back(frame.irradiance[i] - first.irradiance[i]);
                            if (colour) dColour.push_back(colourOf(frame.radiance[i]) - colourOf(first.radiance[i]));
                        }
                        const int indexView = changed.empty() ? -1 : bin.addView(changed.data(), changed.size() * 4);
                        target.radiance = bin.addSparseVec3(count, changed, dRadiance, indexView);
                        target.irradiance = bin.addSparseVec3(count, changed, dIrradiance, indexView);
                        target.colour = colour ? bin.addSparseVec3(count, changed, dColour, indexView) : -1;
                    }
                    targets[{g.mesh, p}].push_back(target);
                }
            }
        if (bin.bytes().size() > kMaxGlbBytes) break;  // reported below
    }
    if (uint64_t(bin.bytes().size()) + 65536 > kMaxGlbBytes) {
        char text[320];
        std::snprintf(text, sizeof text,
                      "the baked asset would exceed the 4 GiB a GLB holds: the asset's own data is %.3g GB and the bake "
                      "%.3g GB a frame over the first %zu frames; render fewer frames (--frames) or a coarser mesh",
                      double(assetBytes) * 1e-9, double(bin.bytes().size() - assetBytes) * 1e-9 / double(frameCount), frameCount);
        throw InputError(kOption, "", text);
    }

    // The targets, and the weights glTF keeps per target.
    const size_t lighting = frameCount - 1;  // targets a lighting-animated mesh gains
    std::set<int> animatedMeshes;
    std::map<int, size_t> ownTargets;  // output mesh → targets before ours
    for (const auto& [mesh, list] : groups)
        for (const Group& g : list) {
            if (!g.animated) continue;
            json& out = doc["meshes"][size_t(g.mesh)];
            ownTargets[g.mesh] = targetCount(out);
            animatedMeshes.insert(g.mesh);
            for (size_t p = 0; p < out["primitives"].size(); ++p) {
                json& primitive = out["primitives"][p];
                if (!primitive.contains("targets")) primitive["targets"] = json::array();
                for (const Target& t : targets[{g.mesh, p}]) {
                    json target = {{"_RADIANCE", t.radiance}, {"_IRRADIANCE", t.irradiance}};
                    if (t.colour >= 0) target[colourName(settings.colourSet)] = t.colour;
                    if (t.position >= 0) target["POSITION"] = t.position;
                    primitive["targets"].push_back(std::move(target));
                }
            }
            if (out.contains("weights"))
                for (size_t i = 0; i < lighting; ++i) out["weights"].push_back(0.0);
        }
    // Nodes showing a mesh that gained targets: their default weights, and every weights channel.
    std::map<int, int> nodeMesh;  // node → output mesh, for the nodes whose mesh gained targets
    if (doc.contains("nodes"))
        for (size_t n = 0; n < doc["nodes"].size(); ++n) {
            json& node = doc["nodes"][n];
            if (!node.contains("mesh") || !animatedMeshes.count(node["mesh"].get<int>())) continue;
            nodeMesh[int(n)] = node["mesh"].get<int>();
            if (node.contains("weights"))
                for (size_t i = 0; i < lighting; ++i) node["weights"].push_back(0.0);
        }

    // A transform file's first pose, where it differs from the file's (the pose the bake is of).
    for (size_t n = 0; n < settings.firstPose.size() && doc.contains("nodes") && n < doc["nodes"].size(); ++n) {
        const Transform given = nodeTransform(doc["nodes"][n]);
        double largest = 1, difference = 0;
        for (int i = 0; i < 16; ++i) {
            largest = std::max(largest, std::fabs(given.m[size_t(i)]));
            difference = std::max(difference, std::fabs(given.m[size_t(i)] - settings.firstPose[n].m[size_t(i)]));
        }
        if (difference > 1e-12 * largest) setNodeTrs(doc["nodes"][n], decomposeTrs(settings.firstPose[n]));
    }
    // Key times are floats in the file: consecutive frames must stay apart there.
    for (size_t k = 1; k < frameCount; ++k)
        if (!(float(times[k]) > float(times[k - 1])))
            throw InputError(kOption, "", "frames " + std::to_string(k - 1) + " and " + std::to_string(k) + " of the run fall on the same "
                                          "single-precision time (glTF key times are floats): render fewer frames or at a lower --fps");
    if (document.json.contains("extensionsUsed") && document.json["extensionsUsed"].is_array())
        for (const json& e : document.json["extensionsUsed"])
            if (e == "KHR_animation_pointer")
                warnings.add(file + ": KHR_animation_pointer channels on morph weights are not given the baked frames' weights");
    // The animation the lighting (and a transform file's motion) goes into.
    if (!animatedMeshes.empty() || !motion.empty()) 
        addLightingAnimation(doc, bin, scene, times, ownTargets, nodeMesh, motion, settings, warnings, file);

    // One buffer, the GLB's binary chunk.
    json buffer = doc.contains("buffers") && !doc["buffers"].empty() ? doc["buffers"][0] : json::object();
    buffer.erase("uri");
    bin.align(4);
    buffer["byteLength"] = bin.bytes().size();
    doc["buffers"] = json::array({std::move(buffer)});
    if (doc.contains("extras") && !doc["extras"].is_object())
        warnings.add(file + ": the root's extras is no object, so asset.glb does not record the bake's units and exposure there");
    else
        doc["extras"]["qsgi"] = {{"units", "_RADIANCE: W m^-2 sr^-1 (B/pi); _IRRADIANCE: W m^-2 (before the albedo)"},
                                 {"frames", frameCount},
                                 {"color", colour ? colourName(settings.colourSet) + " = min(1, exposure * _RADIANCE)" : ""},
                                 {"exposure", settings.exposure}};

    std::string text = doc.dump();
    while (text.size() % 4) text += ' ';
    const uint64_t total = 12 + 8 + uint64_t(text.size()) + 8 + bin.bytes().size();
    if (total > kMaxGlbBytes)
        throw InputError(kOption, "", "the baked asset would exceed the 4 GiB a GLB holds (" + std::to_string(total) + " bytes)");
    std::string glb;
    glb.reserve(size_t(total));
    auto u32 = [&](uint64_t v) {
        const uint32_t w = uint32_t(v);
        glb.append(reinterpret_cast<const char*>(&w), 4);
    };
    glb += "glTF";
    u32(2);
    u32(total);
    u32(text.size());
    u32(0x4E4F534A);  // JSON
    glb += text;
    u32(bin.bytes().size());
    u32(0x004E4942);  // BIN
    glb += bin.bytes();
    if (summary) {
        summary->bytes = glb.size();
        summary->bakeBytes = bin.bytes().size() - assetBytes;
        summary->meshesCopied = copies;
        summary->animatedPrimitives = animatedPrimitives;
    }
    return glb;
}

}  // namespace qsgi
