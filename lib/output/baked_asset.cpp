#include "output/baked_asset.h"

#include <cstdio>
#include <set>

#include "output/bake_animation.h"
#include "output/bake_groups.h"
#include "output/bake_targets.h"
#include "output/baked_asset_parts.h"
#include "output/glb_builder.h"
#include "output/gltf_repack.h"
#include "util/memory.h"

namespace qsgi {

using nlohmann::json;

void checkAssetTakesBake(const GltfDocument& document, const Scene& scene, const BakedAssetSettings& settings,
                         const std::string& sceneFile) {
    const json& doc = document.json;
    if (doc.contains("extensionsUsed") && doc["extensionsUsed"].is_array())
        for (const json& e : doc["extensionsUsed"])
            if (e == "EXT_meshopt_compression")
                throw InputError(sceneFile, "extensionsUsed", "has EXT_meshopt_compression, whose buffers --gltf-out cannot repack");
    std::set<int> meshes;
    for (size_t i = 0; i < scene.frontInstanceCount(); ++i) {  // the back sides are the fronts' (back_sides.h)
        const MeshInstance& instance = scene.instances[i];
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
            for (const char* name : {"_RADIANCE", "_IRRADIANCE", "_BACK_RADIANCE", "_BACK_IRRADIANCE"})
                if (primitives[p].contains("attributes") && primitives[p]["attributes"].contains(name))
                    throw InputError(sceneFile, "meshes[" + std::to_string(mesh) + "].primitives[" + std::to_string(p) + "].attributes." + name,
                                     "is already there (a baked asset?): --gltf-out adds it, so bake the original asset");
    }
    // What the asset will hold at least, known before the render (issue 48): every buffer as its
    // byteLength declares it (a buffer without data is written as zeros) and one frame's bake
    // (E and B/π, 24 bytes a vertex). It is made in memory, and a GLB's length is 32 bits.
    uint64_t declared = 0;
    if (doc.contains("buffers") && doc["buffers"].is_array())
        for (const json& buffer : doc["buffers"])
            if (buffer.is_object() && buffer.contains("byteLength") && buffer["byteLength"].is_number_unsigned())
                declared = saturatingAdd(declared, buffer["byteLength"].get<uint64_t>());
    const uint64_t atLeast = saturatingAdd(declared, saturatingMultiply(scene.frontVertexCount(), 2 * sizeof(Vec3f)));
    const std::string what = "asset.glb (--gltf-out: the scene's buffers, " + formatBytes(declared) + ", and the bake)";
    if (atLeast > kMaxGlbBytes - 65536)
        throw InputError(sceneFile, "buffers", what + " would be " + formatBytes(atLeast) + " or more, beyond the 4 GiB a GLB file holds");
    refuseBeyondMemory(atLeast, sceneFile, "buffers", what);
}

std::string encodeBakedAsset(const GltfDocument& document, const Scene& scene, size_t frameCount,
                             const std::function<BakedFrame(size_t)>& frameAt, const std::vector<NodeMotion>& motion,
                             const BakedAssetSettings& settings, Warnings& warnings, BakedAssetSummary* summary) {
    const std::string file = scene.sourcePath;
    json doc = document.json;
    BinaryBuilder bin(doc);
    packBuffers(document, doc, bin, warnings, file, settings.assetFolder);
    const size_t assetBytes = bin.bytes().size();

    // Two passes over the frames, each reading them in turn (none held but the first): the nodes'
    // groups, then the bake's attributes and targets.
    const BakedFrame first = frameAt(0);
    const MeshGroups groups = groupNodesByBake(doc, scene, first, frameCount, frameAt, warnings, file);
    const BakeTargets targets = addBakedAttributes(doc, bin, document, scene, groups, first, frameCount, frameAt, settings);
    if (uint64_t(bin.bytes().size()) + 65536 > kMaxGlbBytes) {
        char text[320];
        std::snprintf(text, sizeof text,
                      "the baked asset would exceed the 4 GiB a GLB holds: the asset's own data is %.3g GB and the bake "
                      "%.3g GB a frame over the first %zu frames; render fewer frames (--frames) or a coarser mesh",
                      double(assetBytes) * 1e-9, double(bin.bytes().size() - assetBytes) * 1e-9 / double(frameCount), frameCount);
        throw InputError(kOption, "", text);
    }

    const MorphedMeshes morphed = attachTargets(doc, groups, targets, frameCount, settings.colourSet);

    // A transform file's first pose, where it differs from the file's (the pose the bake is of).
    giveFirstPose(doc, settings.firstPose);
    // Key times are floats in the file: consecutive frames must stay apart there.
    for (size_t k = 1; k < frameCount; ++k)
        if (!(float(groups.times[k]) > float(groups.times[k - 1])))
            throw InputError(kOption, "", "frames " + std::to_string(k - 1) + " and " + std::to_string(k) + " of the run fall on the same "
                                          "single-precision time (glTF key times are floats): render fewer frames or at a lower --fps");
    if (document.json.contains("extensionsUsed") && document.json["extensionsUsed"].is_array())
        for (const json& e : document.json["extensionsUsed"])
            if (e == "KHR_animation_pointer")
                warnings.add(file + ": KHR_animation_pointer channels on morph weights are not given the baked frames' weights");
    // The animation the lighting (and a transform file's motion) goes into.
    if (!morphed.ownTargets.empty() || !motion.empty())
        addLightingAnimation(doc, bin, scene, groups.times, morphed.ownTargets, morphed.nodeMesh, motion, settings, warnings, file);

    if (doc.contains("extras") && !doc["extras"].is_object())
        warnings.add(file + ": the root's extras is no object, so asset.glb does not record the bake's units and exposure there");
    else
        doc["extras"]["qsgi"] = {{"units", scene.backSides ? "_RADIANCE, _BACK_RADIANCE: W m^-2 sr^-1 (B/pi); _IRRADIANCE, _BACK_IRRADIANCE: W m^-2 (before the albedo)"
                                                           : "_RADIANCE: W m^-2 sr^-1 (B/pi); _IRRADIANCE: W m^-2 (before the albedo)"},
                                 {"frames", frameCount},
                                 {"color", settings.colourSet >= 0 ? colourName(settings.colourSet) + " = min(1, exposure * _RADIANCE)" : ""},
                                 {"exposure", settings.exposure}};

    const std::string glb = bin.glb();
    if (summary) {
        summary->bytes = glb.size();
        summary->bakeBytes = bin.bytes().size() - assetBytes;
        summary->meshesCopied = groups.copies;
        summary->animatedPrimitives = targets.animatedPrimitives;
    }
    return glb;
}

}  // namespace qsgi
