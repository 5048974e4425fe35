#include "scene/gltf_references.h"

#include <functional>

namespace qsgi {

namespace {

using json = nlohmann::json;

class ReferenceCheck {
public:
    explicit ReferenceCheck(const json& doc) : doc_(doc) {}

    std::vector<GltfFinding> run() {
        if (doc_.contains("scene")) refersTo("", "scene", doc_["scene"], "scenes");
        std::vector<uint8_t> isChild(count("nodes"), 0);
        each("nodes", [&](const json& n, const std::string&) {
            if (n.contains("children") && n["children"].is_array())
                for (const json& c : n["children"])
                    if (c.is_number_unsigned() && c.get<size_t>() < isChild.size()) isChild[c.get<size_t>()] = 1;
        });
        each("scenes", [&](const json& s, const std::string& at) {
            list(at, at + ".nodes", s, "nodes", "nodes");
            // glTF 2.0 (§3.5.2): a scene lists root nodes only.
            if (s.contains("nodes") && s["nodes"].is_array())
                for (size_t k = 0; k < s["nodes"].size(); ++k)
                    if (s["nodes"][k].is_number_unsigned() && s["nodes"][k].get<size_t>() < isChild.size() &&
                        isChild[s["nodes"][k].get<size_t>()])
                        add(at, at + ".nodes[" + std::to_string(k) + "]",
                            "lists node " + s["nodes"][k].dump() + ", which is another node's child, not a root");
        });
        each("nodes", [&](const json& n, const std::string& at) {
            field(at, n, "camera", "cameras");
            field(at, n, "mesh", "meshes");
            field(at, n, "skin", "skins");
            list(at, at + ".children", n, "children", "nodes");
        });
        each("meshes", [&](const json& m, const std::string& at) {
            notEmpty(at, at + ".primitives", m, "primitives");
            if (!m.contains("primitives") || !m["primitives"].is_array()) return;
            for (size_t p = 0; p < m["primitives"].size(); ++p) {
                const json& prim = m["primitives"][p];
                const std::string place = at + ".primitives[" + std::to_string(p) + "]";
                if (!prim.is_object()) continue;
                field(at, prim, "indices", "accessors", place);
                field(at, prim, "material", "materials", place);
                if (prim.contains("attributes") && prim["attributes"].is_object())
                    for (auto it = prim["attributes"].begin(); it != prim["attributes"].end(); ++it)
                        refersTo(at, place + ".attributes." + it.key(), it.value(), "accessors");
                if (prim.contains("targets") && prim["targets"].is_array())
                    for (size_t t = 0; t < prim["targets"].size(); ++t)
                        if (prim["targets"][t].is_object())
                            for (auto it = prim["targets"][t].begin(); it != prim["targets"][t].end(); ++it)
                                refersTo(at, place + ".targets[" + std::to_string(t) + "]." + it.key(), it.value(),
                                         "accessors");
            }
        });
        each("accessors", [&](const json& a, const std::string& at) {
            field(at, a, "bufferView", "bufferViews");
            if (a.contains("byteOffset") && !a.contains("bufferView"))
                add(at, at + ".byteOffset", "is given without a bufferView (glTF allows it only with one)");
            if (a.contains("sparse") && a["sparse"].is_object())
                for (const char* part : {"indices", "values"})
                    if (a["sparse"].contains(part) && a["sparse"][part].is_object())
                        field(at, a["sparse"][part], "bufferView", "bufferViews", at + ".sparse." + part);
        });
        each("bufferViews", [&](const json& v, const std::string& at) { field(at, v, "buffer", "buffers"); });
        each("buffers", [&](const json& b, const std::string& at) {
            if (!b.contains("byteLength"))
                add(at, at, "has no byteLength (glTF requires one)");
            else if (b["byteLength"].is_number() && b["byteLength"].get<double>() < 1)
                add(at, at + ".byteLength", "is 0 (glTF requires at least 1)");
        });
        each("images", [&](const json& i, const std::string& at) { field(at, i, "bufferView", "bufferViews"); });
        each("textures", [&](const json& t, const std::string& at) {
            field(at, t, "source", "images");
            field(at, t, "sampler", "samplers");
        });
        each("materials", [&](const json& m, const std::string& at) {
            for (const char* texture : {"normalTexture", "occlusionTexture", "emissiveTexture"})
                if (m.contains(texture) && m[texture].is_object())
                    field(at, m[texture], "index", "textures", at + "." + texture);
            if (m.contains("pbrMetallicRoughness") && m["pbrMetallicRoughness"].is_object())
                for (const char* texture : {"baseColorTexture", "metallicRoughnessTexture"}) {
                    const json& pbr = m["pbrMetallicRoughness"];
                    if (pbr.contains(texture) && pbr[texture].is_object())
                        field(at, pbr[texture], "index", "textures", at + ".pbrMetallicRoughness." + texture);
                }
        });
        each("skins", [&](const json& s, const std::string& at) {
            field(at, s, "inverseBindMatrices", "accessors");
            field(at, s, "skeleton", "nodes");
            list(at, at + ".joints", s, "joints", "nodes");
        });
        each("animations", [&](const json& a, const std::string& at) {
            const size_t samplers = a.contains("samplers") && a["samplers"].is_array() ? a["samplers"].size() : 0;
            if (samplers)
                for (size_t s = 0; s < samplers; ++s)
                    if (a["samplers"][s].is_object())
                        for (const char* key : {"input", "output"})
                            field(at, a["samplers"][s], key, "accessors", at + ".samplers[" + std::to_string(s) + "]");
            if (a.contains("channels") && a["channels"].is_array())
                for (size_t c = 0; c < a["channels"].size(); ++c) {
                    const json& ch = a["channels"][c];
                    const std::string place = at + ".channels[" + std::to_string(c) + "]";
                    if (!ch.is_object()) continue;
                    if (ch.contains("sampler") && ch["sampler"].is_number_unsigned() &&
                        ch["sampler"].get<size_t>() >= samplers)
                        add(at, place + ".sampler", "refers to sampler " + ch["sampler"].dump() + ", which does not exist");
                    if (ch.contains("target") && ch["target"].is_object())
                        field(at, ch["target"], "node", "nodes", place + ".target");
                }
        });
        each("cameras", [&](const json& c, const std::string& at) {
            // glTF 2.0 (§5.12): exactly the projection its type names.
            const std::string type = c.contains("type") && c["type"].is_string() ? c["type"].get<std::string>() : "";
            for (const char* projection : {"perspective", "orthographic"})
                if (c.contains(projection) && type != projection)
                    add(at, at + "." + projection, std::string("is given but the camera's type is '") + type +
                                                        "' (glTF allows only the projection its type names)");
        });
        // KHR_lights_punctual: a range, where given, is a positive number (its schema's
        // exclusiveMinimum 0). tinygltf reads an absent range as 0, so only the JSON tells them apart.
        if (doc_.contains("extensions") && doc_["extensions"].is_object() && doc_["extensions"].contains("KHR_lights_punctual")) {
            const json& ext = doc_["extensions"]["KHR_lights_punctual"];
            if (ext.is_object() && ext.contains("lights") && ext["lights"].is_array())
                for (size_t l = 0; l < ext["lights"].size(); ++l) {
                    const json& light = ext["lights"][l];
                    const std::string at = "KHR_lights_punctual.lights[" + std::to_string(l) + "]";
                    if (light.is_object() && light.contains("range") &&
                        !(light["range"].is_number() && light["range"].get<double>() > 0))
                        add(at, at + ".range", "is " + light["range"].dump().substr(0, 40) +
                                                   "; a light's range must be a positive number (omit it for no limit)");
                }
        }
        // Top-level arrays, when present, hold at least one object (glTF 2.0 schema, minItems 1).
        for (const char* array : {"accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials",
                                  "meshes", "nodes", "samplers", "scenes", "skins", "textures"})
            notEmpty("", array, doc_, array);
        return std::move(findings_);
    }

private:
    void add(const std::string& object, const std::string& place, const std::string& problem) {
        findings_.push_back({object, place, problem});
    }

    size_t count(const char* array) const {
        return doc_.contains(array) && doc_[array].is_array() ? doc_[array].size() : 0;
    }

    // A reference to `array`: an index below its size. Values that are no index at all were
    // refused before (refuseNegativeIndices); anything else is left to the reader.
    void refersTo(const std::string& object, const std::string& place, const json& value, const char* array) {
        if (!value.is_number_unsigned()) return;
        const size_t index = value.get<size_t>();
        if (index >= count(array))
            add(object, place, "refers to " + std::string(array) + "[" + std::to_string(index) + "], which does not exist (the file has " +
                                   std::to_string(count(array)) + ")");
    }

    void field(const std::string& object, const json& owner, const char* key, const char* array,
               const std::string& ownerPlace = "") {
        if (owner.contains(key)) refersTo(object, (ownerPlace.empty() ? object : ownerPlace) + "." + key, owner[key], array);
    }

    void list(const std::string& object, const std::string& place, const json& owner, const char* key, const char* array) {
        if (!owner.contains(key) || !owner[key].is_array()) return;
        notEmpty(object, place, owner, key);
        for (size_t k = 0; k < owner[key].size(); ++k)
            refersTo(object, place + "[" + std::to_string(k) + "]", owner[key][k], array);
    }

    void notEmpty(const std::string& object, const std::string& place, const json& owner, const char* key) {
        if (owner.contains(key) && owner[key].is_array() && owner[key].empty())
            add(object, place, "is an empty array (glTF requires at least one element where the array is given)");
    }

    void each(const char* array, const std::function<void(const json&, const std::string&)>& visit) const {
        if (!doc_.contains(array) || !doc_[array].is_array()) return;
        for (size_t i = 0; i < doc_[array].size(); ++i)
            if (doc_[array][i].is_object()) visit(doc_[array][i], std::string(array) + "[" + std::to_string(i) + "]");
    }

    const json& doc_;
    std::vector<GltfFinding> findings_;
};

}  // namespace

std::vector<GltfFinding> findReferenceProblems(const nlohmann::json& doc) { return ReferenceCheck(doc).run(); }

}  // namespace qsgi
