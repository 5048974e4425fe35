// Stand-ins for the first pass at covered vertices (docs/design.md §5.1, issue 47). A vertex is
// covered when its start point lies inside closed geometry — the floor under a block standing on
// it (FinalGather::coveredFromKept). No light reaches it, so its first pass is about 0, and its
// own output stays so; but the gather reads the first pass interpolated across triangles, and a
// floor triangle cut by the block's foot has a covered corner: read as is, its 0 darkens the
// strip outside the foot, which the block's lowest vertices see at grazing angles through half
// their hemisphere (their rays land within a millimetre of the foot). So for the gather's lookups
// only, a covered vertex takes the mean of its visible neighbours on the same surface, and
// covered vertices further in take their covered neighbours' stand-ins, ring by ring: the visible
// field carried on under the foot, as a linear interpolation on the visible side of the cut needs.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

// Replaces firstPass[v] at every covered vertex that a chain of same-surface neighbours (sharing
// a triangle, normals within 45°, as the own surface's rule) joins to a visible one: the mean of
// the neighbours known one ring earlier, each neighbour counted once per triangle it shares with
// v, in triangle order. Covered vertices no chain reaches keep their value. Depends on the
// geometry and the flags alone: any thread count, and an update, give the same bits.
void fillCoveredFirstPass(const Scene& scene, const std::vector<uint8_t>& covered, std::vector<Vec3f>& firstPass);

}  // namespace qsgi
