// Both sides of a doubleSided surface (issue 57). glTF's doubleSided says a surface's back is lit
// and shown as its front with the normal reversed. qsgi gives each such instance a copy with
// reversed winding and negated normals, its back side, so that every stage — photons, start
// points, disc regions, direct light, the estimators, the gather, the camera — lights it as a
// surface of its own, with no rule of its own. Where the two coincide a ray meets the one that
// faces it (SceneBvh's filters); the mesh topology keeps the two apart (MeshTopology(const
// Scene&)); and the cover test stays geometric: a ray that meets a back side has met the back of
// the surface (FinalGather), so the inside of a closed doubleSided mesh is covered and dark.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

// Appends the back sides of every instance whose material is doubleSided, after every instance
// there is, and sets scene.backSides (left empty when there are none: the scene is unchanged).
// Called once, after any refinement and before the scene is solved. An emissive material's back
// emits nothing: glTF's emission, as qsgi's, is the front's (docs/inputs.md). An instance that
// closes a volume with an opaque material gets none: its inside, which no light reaches, would
// be covered and 0 (its outputs' back values are 0 all the same), and costs nothing.
void addBackSides(Scene& scene);
// The instances addBackSides gives a back side: doubleSided, not sealed.
std::vector<uint8_t> instancesWithBackSides(const Scene& scene);
// The same with the choice given, one per instance: a refined copy of a scene (the vertex fit's
// sampling mesh) takes its original's, so that the two keep matching instances.
void addBackSides(Scene& scene, const std::vector<uint8_t>& which);

}  // namespace qsgi
