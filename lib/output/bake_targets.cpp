#include "output/bake_targets.h"

#include <algorithm>
#include <cstdint>
#include <set>
#include <string>

#include "output/baked_asset_parts.h"
#include "output/refined_attributes.h"
#include "scene/gltf_accessor.h"

namespace qsgi {

using nlohmann::json;

namespace {

size_t targetCount(const json& mesh) {
    const json& p0 = mesh["primitives"][0];
    return p0.contains("targets") ? p0["targets"].size() : 0;
}

}  // namespace

BakeTargets addBakedAttributes(json& doc, BinaryBuilder& bin, const GltfDocument& document, const Scene& scene,
                               const MeshGroups& groups, const BakedFrame& first, size_t frameCount,
                               const std::function<BakedFrame(size_t)>& frameAt, const BakedAssetSettings& settings) {
    const bool colour = settings.colourSet >= 0;
    auto colourOf = [&](const Vec3f& radiance) {
        Vec3f c;
        for (int i = 0; i < 3; ++i) c[i] = float(std::clamp(double(radiance[i]) * settings.exposure, 0.0, 1.0));
        return c;
    };
    BakeTargets result;
    auto& targets = result.targets;
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
    size_t& animatedPrimitives = result.animatedPrimitives;
    const AccessorReader reader(document, scene.sourcePath);
    const bool anyAnimated = groups.anyAnimated();
    // A doubleSided primitive's back values.
    auto hasBack = [&](const MeshInstance& instance) { return !first.backRadiance.empty() && scene.showsBack(instance); };
    for (size_t k = 0; k < (anyAnimated ? frameCount : 1); ++k) {
        const BakedFrame frame = k == 0 ? first : frameAt(k);
        for (const auto& [mesh, list] : groups.groups)
            for (const BakeGroup& g : list) {
                if (k > 0 && !g.animated) continue;
                json& out = doc["meshes"][size_t(g.mesh)];
                const auto& instances = groups.instancesOf(mesh, g.nodes[0]);
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
                        if (hasBack(*instance)) {
                            attributes["_BACK_RADIANCE"] = bin.addVec3(&frame.backRadiance[instance->firstVertex], count);
                            attributes["_BACK_IRRADIANCE"] = bin.addVec3(&frame.backIrradiance[instance->firstVertex], count);
                        }
                        if (colour) {
                            std::vector<Vec3f> c(count);
                            for (size_t v = 0; v < count; ++v) c[v] = colourOf(frame.radiance[instance->firstVertex + v]);
                            attributes[colourName(settings.colourSet)] = bin.addVec3(c.data(), count);
                        }
                        if (g.animated) ++animatedPrimitives;
                        continue;
                    }
                    BakeTarget target{-1, -1, -1, zeroPositionsOf(primitive, count)};
                    if (!instance) {
                        target.radiance = bin.addZeroVec3(count);
                        target.irradiance = bin.addZeroVec3(count);
                    } else {
                        std::vector<uint32_t> changed;
                        std::vector<Vec3f> dRadiance, dIrradiance, dColour, dBackRadiance, dBackIrradiance;
                        const bool back = hasBack(*instance);
                        for (size_t v = 0; v < count; ++v) {
                            const size_t i = instance->firstVertex + v;
                            if (frame.radiance[i] == first.radiance[i] && frame.irradiance[i] == first.irradiance[i] &&
                                (!back || (frame.backRadiance[i] == first.backRadiance[i] &&
                                           frame.backIrradiance[i] == first.backIrradiance[i])))
                                continue;
                            changed.push_back(uint32_t(v));
                            dRadiance.push_back(frame.radiance[i] - first.radiance[i]);
                            dIrradiance.push_back(frame.irradiance[i] - first.irradiance[i]);
                            if (colour) dColour.push_back(colourOf(frame.radiance[i]) - colourOf(first.radiance[i]));
                            if (back) {
                                dBackRadiance.push_back(frame.backRadiance[i] - first.backRadiance[i]);
                                dBackIrradiance.push_back(frame.backIrradiance[i] - first.backIrradiance[i]);
                            }
                        }
                        const int indexView = changed.empty() ? -1 : bin.addView(changed.data(), changed.size() * 4);
                        target.radiance = bin.addSparseVec3(count, changed, dRadiance, indexView);
                        target.irradiance = bin.addSparseVec3(count, changed, dIrradiance, indexView);
                        target.colour = colour ? bin.addSparseVec3(count, changed, dColour, indexView) : -1;
                        if (back) {
                            target.backRadiance = bin.addSparseVec3(count, changed, dBackRadiance, indexView);
                            target.backIrradiance = bin.addSparseVec3(count, changed, dBackIrradiance, indexView);
                        }
                    }
                    targets[{g.mesh, p}].push_back(target);
                }
            }
        if (bin.bytes().size() > kMaxGlbBytes) break;  // reported by the caller
    }
    return result;
}

MorphedMeshes attachTargets(json& doc, const MeshGroups& groups, const BakeTargets& targets, size_t frameCount,
                            int colourSet) {
    const size_t lighting = frameCount - 1;  // targets a lighting-animated mesh gains
    std::set<int> animatedMeshes;
    MorphedMeshes result;
    std::map<int, size_t>& ownTargets = result.ownTargets;
    for (const auto& [mesh, list] : groups.groups)
        for (const BakeGroup& g : list) {
            if (!g.animated) continue;
            json& out = doc["meshes"][size_t(g.mesh)];
            ownTargets[g.mesh] = targetCount(out);
            animatedMeshes.insert(g.mesh);
            for (size_t p = 0; p < out["primitives"].size(); ++p) {
                json& primitive = out["primitives"][p];
                if (!primitive.contains("targets")) primitive["targets"] = json::array();
                const auto made = targets.targets.find({g.mesh, p});
                if (made == targets.targets.end()) continue;
                for (const BakeTarget& t : made->second) {
                    json target = {{"_RADIANCE", t.radiance}, {"_IRRADIANCE", t.irradiance}};
                    if (t.colour >= 0) target[colourName(colourSet)] = t.colour;
                    if (t.backRadiance >= 0) target["_BACK_RADIANCE"] = t.backRadiance, target["_BACK_IRRADIANCE"] = t.backIrradiance;
                    if (t.position >= 0) target["POSITION"] = t.position;
                    primitive["targets"].push_back(std::move(target));
                }
            }
            if (out.contains("weights"))
                for (size_t i = 0; i < lighting; ++i) out["weights"].push_back(0.0);
        }
    // Nodes showing a mesh that gained targets: their default weights, and every weights channel.
    std::map<int, int>& nodeMesh = result.nodeMesh;
    if (doc.contains("nodes"))
        for (size_t n = 0; n < doc["nodes"].size(); ++n) {
            json& node = doc["nodes"][n];
            if (!node.contains("mesh") || !animatedMeshes.count(node["mesh"].get<int>())) continue;
            nodeMesh[int(n)] = node["mesh"].get<int>();
            if (node.contains("weights"))
                for (size_t i = 0; i < lighting; ++i) node["weights"].push_back(0.0);
        }
    return result;
}

}  // namespace qsgi
