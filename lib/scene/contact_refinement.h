// --refine-contacts DISTANCE (issue 47 item 3): vertices where the light changes within a triangle.
// Radiosity lives at vertices and a viewer interpolates it linearly across each triangle; where two
// surfaces touch or nearly do — a block's foot on a floor, a character's feet, the ceiling round a
// fixture mounted just below it — the light falls off within a few centimetres, and a floor triangle
// the foot cuts, or a block's 15 cm bottom row, smears one dark or lit vertex over its whole area.
// So every edge that passes within DISTANCE of another piece of surface (pieces joined across shared
// edges: MeshTopology::edgeConnectedPieces) in any frame of the animation is bisected until it is at
// most DISTANCE / 2 long, with --subdivide's conforming longest-edge bisection (mesh_refinement.h).
//
// Judged on the whole animation (every frame, so that every chunk of a split run refines alike, and
// the floor along a mover's path is refined), on the unrefined geometry's poses; an edge's place in a
// pose is its corners' there, a new vertex its edge's midpoint (exact for rigid movers, the
// skinned mesh's chord for a deforming one). Distance is measured at points along the edge no more
// than DISTANCE / 4 apart in any pose, so an edge passing nearer than DISTANCE only between them is
// missed by at most DISTANCE / 8; an edge longer than 4096 such spacings is split without asking
// (its halves are asked). Where the poses' positions would take more than 1 GiB, evenly spaced
// frames are judged (the first and last always). RenderJob refuses a DISTANCE below 10⁻⁴ of the
// scene's size, which would refine contact lines into more triangles than any run can hold.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>

#include "scene/mesh_refinement.h"
#include "scene/scene.h"

namespace qsgi {

// Edges are split down to this share of DISTANCE.
constexpr double kContactEdgeShare = 0.5;

struct ContactRefinementReport {
    RefinementReport mesh;
    int posesJudged = 0;  // frames whose poses were judged (the rest pose among them)
};

// Refines `scene` (in its rest pose; left in it) near contacts over frames 0…lastFrame; nullopt,
// the scene unchanged, when more than `triangleLimit` triangles would be made.
std::optional<ContactRefinementReport> refineContacts(Scene& scene, double distance, int lastFrame,
                                                      const std::function<Pose(int)>& poseAt, size_t triangleLimit);

}  // namespace qsgi
