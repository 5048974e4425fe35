// --subdivide's meshes in asset.glb (lib/output/baked_asset.h): the bake is per refined vertex, so
// a refined primitive is written whole — the file's attributes and morph targets resampled onto
// the refined vertices, the skin as the refinement blended it, the refined triangles.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "output/glb_builder.h"
#include "scene/gltf_accessor.h"
#include "scene/scene.h"

namespace qsgi {

// A primitive as --subdivide refined it (MeshInstance::refinedFrom): every attribute and morph
// target the file gives, its own vertices as they are and each new vertex by the refinement's one
// rule (refinedValue: the mean of its edge's two, a normal's and a tangent's direction
// renormalised in double, a tangent's handedness its first corner's), written as floats; the
// skin's joints and weights as the refinement blended them; the refined triangles as indices.
// `place` names the primitive in messages.
nlohmann::json refinedPrimitive(nlohmann::json primitive, const nlohmann::json& doc, BinaryBuilder& bin, const AccessorReader& reader,
                                const Scene& scene, const MeshInstance& inst, const std::string& place);

}  // namespace qsgi
