// The user's own glTF file back with the bake in it (--gltf-out, issue 35; docs/outputs.md):
// asset.glb. Every object of the input is kept as the file holds it (its JSON is edited, never
// re-encoded from a model), with:
//   - on each rendered primitive, the attributes _RADIANCE (B/π, W m⁻² sr⁻¹) and _IRRADIANCE (E,
//     W m⁻², the light arriving before the albedo: what a textured asset's shader multiplies by its
//     texture), float RGB, and on request a new COLOR_n set = min(1, exposure · B/π);
//   - for an animation, frame 0's values as those attributes and one morph target per later frame
//     holding the difference from frame 0 as a sparse accessor (only the vertices whose values
//     changed), driven by a STEP weights channel (frame k shows target k − 1 at weight 1). Each
//     such target also holds a POSITION of zeros (no bufferView, min and max 0: no bytes; one
//     accessor per vertex count; none on a primitive without POSITION), without which Blender's
//     importer makes no shape key of it. Targets
//     are appended after a mesh's own; the mesh's and its nodes' default weights and every
//     animation's weights output are extended with zeros for them, and the channel goes into the
//     animation that played (merged with its own weights channel for that node) or, for a transform
//     file or all animations at once, a new animation "qsgi" that also holds the transform file's
//     motion as the moved nodes' translation, rotation and scale (LINEAR at the frames);
//   - a mesh shared by several nodes is copied only for the nodes whose bakes differ from the
//     first's (in any frame);
//   - one binary buffer: the input's buffers placed one after another, then its images' files (an
//     image's uri becomes a bufferView), then the bake.
// A GLB holds at most 4 GiB; beyond, encodeBakedAsset throws (the message gives the bytes).
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "output/bake_inputs.h"
#include "scene/gltf_document.h"
#include "scene/scene.h"
#include "util/error.h"

namespace qsgi {

// What the encoding came to, for the run's log and the user.
struct BakedAssetSummary {
    size_t bytes = 0;             // the whole file
    size_t bakeBytes = 0;         // of which the frame-0 attributes, targets and weights channels
    size_t meshesCopied = 0;      // copies made for nodes whose bakes differ
    size_t animatedPrimitives = 0;  // primitives given per-frame targets
};

// Throws InputError (naming "gltf_out (--gltf-out)" or the scene file) when the asset cannot take
// the bake: a primitive already holding _RADIANCE or _IRRADIANCE (a baked asset: bake the
// original), COLOR_n already there or not following COLOR_(n−1), EXT_meshopt_compression (whose
// buffers cannot be repacked). Called before the render, so that nothing is computed for an asset
// that cannot be written.
void checkAssetTakesBake(const GltfDocument& document, const Scene& scene, const BakedAssetSettings& settings,
                         const std::string& sceneFile);

// The GLB's bytes. `frameAt(k)` gives frame k of `frameCount` (it is called twice per frame: the
// frames are read, not held, so a long animation costs two frames of memory). Throws InputError
// when the file would exceed a GLB's 4 GiB.
std::string encodeBakedAsset(const GltfDocument& document, const Scene& scene, size_t frameCount,
                             const std::function<BakedFrame(size_t)>& frameAt, const std::vector<NodeMotion>& motion,
                             const BakedAssetSettings& settings, Warnings& warnings, BakedAssetSummary* summary = nullptr);

}  // namespace qsgi
