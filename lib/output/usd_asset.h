// asset.usda (--usd-out, issue 46; docs/outputs.md): the scene's meshes with the bake as
// time-sampled vertex colours, in the USD text format, for tools that play per-frame colours on
// import (Blender's USD importer does; it freezes a glTF's colour morph targets at the first frame).
//
// Layout (names from the glTF, made USD identifiers and unique among siblings):
//   /Scene                       Xform, the default prim
//   /Scene/Materials/<material>  a UsdPreviewSurface per material that shows the bake by emission:
//                                emissiveColor from a UsdPrimvarReader_float3 of "radiance",
//                                diffuse black, ior 1 (no specular lobe)
//   /Scene/<node>/<mesh>         Mesh per placed glTF primitive: one USD point per qsgi vertex (never
//                                welded, so seams keep their values), triangles, no subdivision;
//                                primvars radiance (B/π) and irradiance (E), color3f, vertex
//                                interpolation, one time sample at every frame (time code = frame
//                                number: USD interpolates between samples, so none may be missing)
// A rigid mesh keeps its object-space points (and normals, when the file gives them) and carries
// its node's world transform, time-sampled where it moves (a singular one, a hidden node, collapses
// it to the node's origin, as qsgi does); a skinned or morphing one has world-space points and
// normals, time-sampled where they move. Triangles that name a vertex twice are left out.
// custom int qsgi:firstVertex / qsgi:vertexCount say which vertices of the frame PLYs a mesh holds.
// Floats are written in shortest round-trip form.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "output/ply_reader.h"
#include "scene/scene.h"

namespace qsgi {

struct UsdAssetSettings {
    int first = 0, last = 0;  // the frames written, as time codes
    double fps = 0;           // the animation's (timeCodesPerSecond); 0: USD's default of 24
    std::string source;       // the scene file, for the layer's doc string
    // The glTF's mesh names by index (shorter, or empty for a scene built in code: "Mesh").
    std::vector<std::string> meshNames;
    // Every node's world transform at a frame (the animation's pose).
    std::function<std::vector<Transform>(int frame)> nodeWorldAt;
    // Frame data held at once, in bytes: the meshes are written in groups whose frames fit, each
    // group reading every frame's PLY once. A mesh larger than the budget alone is still written
    // whole (its frames held).
    uint64_t memoryBudget = uint64_t(1) << 30;
};

struct UsdAssetSummary {
    uint64_t bytes = 0;
    size_t meshes = 0, points = 0, frames = 0;
    size_t framePasses = 0;  // how many times every frame's PLY was read
};

// Writes the layer in pieces to `put`. `frameAt(frame)` gives a frame's PLY (checked to hold the
// scene's vertices).
void writeUsdAsset(const Scene& scene, const UsdAssetSettings& settings,
                   const std::function<VertexRadiosityPly(int frame)>& frameAt,
                   const std::function<void(std::string_view)>& put, UsdAssetSummary* summary = nullptr);

}  // namespace qsgi
