#include "output/bake_groups.h"

#include <algorithm>
#include <cstring>
#include <iterator>
#include <utility>

namespace qsgi {

using nlohmann::json;

namespace {

// Whether instance a's bake in frame x equals instance b's in frame y, bit for bit.
bool sameBake(const BakedFrame& x, const MeshInstance& a, const BakedFrame& y, const MeshInstance& b) {
    if (a.vertexCount != b.vertexCount) return false;
    const size_t bytes = size_t(a.vertexCount) * sizeof(Vec3f);
    const bool backs = !x.backRadiance.empty() && !y.backRadiance.empty();
    return std::memcmp(&x.radiance[a.firstVertex], &y.radiance[b.firstVertex], bytes) == 0 &&
           std::memcmp(&x.irradiance[a.firstVertex], &y.irradiance[b.firstVertex], bytes) == 0 &&
           (!backs || (std::memcmp(&x.backRadiance[a.firstVertex], &y.backRadiance[b.firstVertex], bytes) == 0 &&
                       std::memcmp(&x.backIrradiance[a.firstVertex], &y.backIrradiance[b.firstVertex], bytes) == 0));
}

size_t primitiveCount(const json& doc, int mesh) { return doc["meshes"][size_t(mesh)]["primitives"].size(); }

}  // namespace

bool MeshGroups::anyAnimated() const {
    return std::any_of(groups.begin(), groups.end(), [](const auto& entry) {
        return std::any_of(entry.second.begin(), entry.second.end(), [](const BakeGroup& g) { return g.animated; });
    });
}

MeshGroups groupNodesByBake(json& doc, const Scene& scene, const BakedFrame& first, size_t frameCount,
                            const std::function<BakedFrame(size_t)>& frameAt, Warnings& warnings, const std::string& file) {
    MeshGroups result;
    // Which nodes show which glTF mesh, in the order the scene placed them.
    std::map<int, MeshUse>& uses = result.uses;
    for (size_t i = 0; i < scene.frontInstanceCount(); ++i) {  // the back sides are the fronts' (back_sides.h)
        const MeshInstance& instance = scene.instances[i];
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
    std::map<int, std::vector<BakeGroup>>& groups = result.groups;
    for (const auto& [mesh, use] : uses) groups[mesh].push_back(BakeGroup{mesh, use.nodes, false});
    std::vector<double>& times = result.times;
    times.resize(frameCount);
    for (size_t k = 0; k < frameCount; ++k) {
        const BakedFrame frame = k == 0 ? first : frameAt(k);
        times[k] = frame.seconds;
        for (auto& [mesh, list] : groups) {
            std::vector<BakeGroup> split;
            for (const BakeGroup& g : list) {
                const size_t begin = split.size();
                for (const int node : g.nodes) {
                    auto same = [&](const BakeGroup& other) {
                        const auto& a = result.instancesOf(mesh, node);
                        const auto& b = result.instancesOf(mesh, other.nodes[0]);
                        for (size_t p = 0; p < a.size(); ++p) {
                            if (!a[p] != !b[p]) return false;
                            if (a[p] && (a[p]->refinedFrom != b[p]->refinedFrom || !sameBake(frame, *a[p], frame, *b[p]))) return false;
                        }
                        return true;
                    };
                    auto match = std::find_if(split.begin() + std::ptrdiff_t(begin), split.end(), same);
                    if (match == split.end()) split.push_back(BakeGroup{-1, {node}, g.animated});
                    else match->nodes.push_back(node);
                }
            }
            for (BakeGroup& g : split) {
                if (g.animated || k == 0) continue;
                for (const MeshInstance* instance : result.instancesOf(mesh, g.nodes[0]))
                    if (instance && !sameBake(frame, *instance, first, *instance)) g.animated = true;
            }
            list = std::move(split);
        }
    }
    // A primitive without a vertex count (no attribute with an accessor) cannot take the targets
    // every primitive of a morphing mesh must have: its mesh keeps frame 0's lighting.
    for (auto& [mesh, list] : groups)
        for (BakeGroup& g : list) {
            if (!g.animated) continue;
            const auto& instances = result.instancesOf(mesh, g.nodes[0]);
            for (size_t p = 0; p < instances.size(); ++p)
                if (!instances[p] && vertexCountOf(doc, doc["meshes"][size_t(mesh)]["primitives"][p]) == 0) {
                    g.animated = false;
                    warnings.add(file + ": meshes[" + std::to_string(mesh) + "].primitives[" + std::to_string(p) +
                                 "] has no vertices to give morph targets, so the mesh shows only the first frame's lighting");
                }
        }
    // The first group keeps the mesh; the others get copies, their nodes pointed at them.
    size_t& copies = result.copies;
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
    return result;
}

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

}  // namespace qsgi
