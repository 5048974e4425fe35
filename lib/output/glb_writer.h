// frame_NNNN.glb (--gltf-out, docs/design.md §7): the frame's posed geometry with the solution on it, for
// glTF viewers and engines. The outgoing radiance B/π, exactly, in the custom attribute _RADIANCE
// and the irradiance E in _IRRADIANCE (linear float RGB). COLOR_0, on a KHR_materials_unlit
// material with base colour 1, is min(1, exposure · B/π): a viewer shows the solution without
// lighting it again. COLOR_0 is not B/π itself because glTF requires colours in 0..1 (the
// Khronos validator reports emitters' B/π of 12 as errors), so COLOR_0 carries the preview's
// exposure, the one the PLY colours use (fixed at frame 0, so frames do not flicker), recorded in
// the mesh's extras as qsgi.exposure. Positions are stored relative to the scene's worldOrigin,
// which the root node's translation adds back (float positions stay precise far from the
// origin). Encoded with tinygltf.
#pragma once

#include <string>

#include "estimate/vertex_radiosity.h"
#include "output/ply_writer.h"
#include "scene/scene.h"

namespace qsgi {

// The file's bytes (OutputDirectory::write puts them on disk).
std::string encodeVertexRadiosityGlb(const Scene& scene, const VertexRadiosity& result, const PreviewTonemap& tonemap);

}  // namespace qsgi
