// The bake on asset.glb's meshes (lib/output/baked_asset.h): frame 0's values as attributes of
// every rendered primitive (_RADIANCE, _IRRADIANCE and on request COLOR_n), and for an animated
// group each later frame's difference from frame 0 as a sparse morph target (only the vertices
// whose values changed), appended after the mesh's own targets. Each such target also holds a
// POSITION of zeros that takes no bytes, without which Blender's importer makes no shape key of it.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/bake_groups.h"
#include "output/bake_inputs.h"
#include "output/glb_builder.h"
#include "scene/gltf_document.h"
#include "scene/scene.h"

namespace qsgi {

// One later frame's target of one primitive, before it is attached to its mesh.
struct BakeTarget {
    int radiance, irradiance, colour, position;  // accessors (-1: none)
    int backRadiance = -1, backIrradiance = -1;  // a doubleSided primitive's (lib/scene/back_sides.h)
};

struct BakeTargets {
    std::map<std::pair<int, size_t>, std::vector<BakeTarget>> targets;  // (output mesh, primitive) → per later frame
    size_t animatedPrimitives = 0;                                       // primitives given per-frame targets
};

// The second pass over the frames (after groupNodesByBake's): frame 0's values as attributes,
// later frames' differences as sparse targets (each frame read once more; `first` is frameAt(0)).
// A refined primitive is first written whole (lib/output/refined_attributes.h). Stops after a
// frame once the binary chunk is beyond a GLB's 4 GiB: the caller reports it.
BakeTargets addBakedAttributes(nlohmann::json& doc, BinaryBuilder& bin, const GltfDocument& document, const Scene& scene,
                               const MeshGroups& groups, const BakedFrame& first, size_t frameCount,
                               const std::function<BakedFrame(size_t)>& frameAt, const BakedAssetSettings& settings);

// The meshes that gained targets (the output meshes of the animated groups).
struct MorphedMeshes {
    std::map<int, size_t> ownTargets;  // output mesh → targets before ours
    std::map<int, int> nodeMesh;       // node → output mesh, for the nodes whose mesh gained targets
};

// The targets on their meshes, and the weights glTF keeps per target (the meshes' and their
// nodes' default weights) extended with zeros for them.
MorphedMeshes attachTargets(nlohmann::json& doc, const MeshGroups& groups, const BakeTargets& targets, size_t frameCount,
                            int colourSet);

}  // namespace qsgi
