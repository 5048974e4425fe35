// asset.glb's container (glTF 2.0 §4.4): one binary chunk, built up with the JSON's bufferViews
// and accessors into it, then framed with the JSON as a GLB. The encoding of the bake
// (lib/output/baked_asset.h) adds everything through it.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "util/vecmath.h"

namespace qsgi {

// glTF's numbers for FLOAT and UNSIGNED_INT components and for the two buffer-view targets.
inline constexpr int kFloat = 5126, kUnsignedInt = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;
// A GLB's length is a uint32 (glTF 2.0 §4.4.3.1).
inline constexpr uint64_t kMaxGlbBytes = 0xFFFFFFFFull;

// The binary chunk and the JSON's bufferViews and accessors into it.
class BinaryBuilder {
public:
    explicit BinaryBuilder(nlohmann::json& doc) : doc_(doc) {
        if (!doc_.contains("bufferViews")) doc_["bufferViews"] = nlohmann::json::array();
        if (!doc_.contains("accessors")) doc_["accessors"] = nlohmann::json::array();
    }
    std::string& bytes() { return bin_; }
    void align(size_t to) { bin_.resize((bin_.size() + to - 1) / to * to, '\0'); }

    // `target` 34962 (ARRAY_BUFFER) for vertex attributes' views, 0 for others (sparse parts,
    // animation keys, images), which glTF leaves without one.
    int addView(const void* data, size_t size, int target = 0) {
        align(4);
        nlohmann::json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", size}};
        if (target) view["target"] = target;
        bin_.append(static_cast<const char*>(data), size);
        doc_["bufferViews"].push_back(std::move(view));
        return int(doc_["bufferViews"].size()) - 1;
    }
    int addAccessor(nlohmann::json accessor) {
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
        nlohmann::json accessor = {{"componentType", kFloat}, {"count", count}, {"type", "VEC3"}};
        if (bounds) {
            accessor["min"] = {0, 0, 0};
            accessor["max"] = {0, 0, 0};
        }
        return addAccessor(std::move(accessor));
    }
    // Zeros but at `indices` (strictly increasing), which hold `values`.
    int addSparseVec3(size_t count, const std::vector<uint32_t>& indices, const std::vector<Vec3f>& values, int indexView) {
        nlohmann::json accessor = {{"componentType", kFloat}, {"count", count}, {"type", "VEC3"}};
        if (!indices.empty())
            accessor["sparse"] = {{"count", indices.size()},
                                  {"indices", {{"bufferView", indexView}, {"componentType", kUnsignedInt}}},
                                  {"values", {{"bufferView", addView(values.data(), values.size() * sizeof(Vec3f))}}}};
        return addAccessor(std::move(accessor));
    }
    int addScalars(const std::vector<float>& values, bool bounds) {
        nlohmann::json accessor = {{"bufferView", addView(values.data(), values.size() * sizeof(float))}, {"componentType", kFloat},
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

    // The file: the JSON, its buffers made the one that is the binary chunk, and the chunk. Throws
    // InputError when it would exceed a GLB's 4 GiB.
    std::string glb();

private:
    nlohmann::json& doc_;
    std::string bin_;
};

}  // namespace qsgi
