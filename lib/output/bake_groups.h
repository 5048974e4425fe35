// Which nodes share a mesh's bake in asset.glb (lib/output/baked_asset.h). glTF puts vertex
// attributes on a mesh, which several nodes may show: the nodes of a mesh fall into groups whose
// bakes are equal in every frame; the first group keeps the mesh and each other group gets a copy.
// A group is animated, and its mesh gains the lighting's morph targets, when some frame's bake
// differs from frame 0's.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "output/bake_inputs.h"
#include "scene/scene.h"
#include "util/error.h"

namespace qsgi {

// The rendered nodes of one glTF mesh, each with its instances by primitive (nullptr: skipped).
struct MeshUse {
    std::vector<int> nodes;
    std::map<int, std::vector<const MeshInstance*>> instances;  // node → by primitive
};

// Nodes of one glTF mesh whose bakes are equal in every frame.
struct BakeGroup {
    int mesh = -1;  // the output mesh: the input's for the first group, a copy for the others
    std::vector<int> nodes;
    bool animated = false;
};

struct MeshGroups {
    std::map<int, MeshUse> uses;                   // glTF mesh → the nodes showing it, in the order the scene placed them
    std::map<int, std::vector<BakeGroup>> groups;  // glTF mesh → its groups
    std::vector<double> times;                     // every frame's animation time, read on the way
    size_t copies = 0;                             // meshes copied for groups after the first

    // The instances node `node` shows of glTF mesh `mesh`, by primitive.
    const std::vector<const MeshInstance*>& instancesOf(int mesh, int node) const { return uses.at(mesh).instances.at(node); }
    bool anyAnimated() const;
};

// The groups, from every frame (`first` is frameAt(0), which is not called again), and the copies
// of the meshes in `doc`, their nodes pointed at them. A group with a primitive that cannot take
// morph targets (no vertex count) is not animated, which `warnings` says.
MeshGroups groupNodesByBake(nlohmann::json& doc, const Scene& scene, const BakedFrame& first, size_t frameCount,
                            const std::function<BakedFrame(size_t)>& frameAt, Warnings& warnings, const std::string& file);

// A primitive's vertex count, from its POSITION or else any attribute whose accessor exists (0:
// none tells it).
size_t vertexCountOf(const nlohmann::json& doc, const nlohmann::json& primitive);

}  // namespace qsgi
