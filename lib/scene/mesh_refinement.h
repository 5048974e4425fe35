// --subdivide LENGTH (issue 35): refines every triangle with an edge longer than LENGTH, so that the
// mesh is fine enough to carry the lighting (mesh_resolution.h says when it is not).
//
// Decided once, on the pose the scene is in (RenderJob calls it on the rest pose, the run's first
// frame), and then part of the scene: every frame, the PLY, EXR and glTF outputs and the run's
// fingerprint hold the refined mesh, and incremental frames are computed on it as on any mesh.
//
// Longest-edge bisection: each pass splits every triangle whose longest edge exceeds LENGTH at that
// edge's midpoint, until none does. An edge is thus split exactly when it is longer than LENGTH,
// always at its midpoint, whichever of its triangles reaches it first: both triangles of an edge,
// and both sides of a seam (corners duplicated for their normals or UVs), end with the same points,
// and no T-junction is left.
// A new vertex takes the mean of its edge's corners (refinedValue, the one rule, which asset.glb's
// attributes of the file follow too): object-space position and normal (renormalised), every morph
// target's deltas, and for a skinned mesh the union of both corners' joint influences at half
// weight, cut to the instance's influence count (four per JOINTS_n set) by weight and renormalised
// to sum 1. Lengths are measured on the current world positions, a new
// vertex's taken as its corners' mean (where a skinned mesh's midpoint is posed differs slightly).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

// How a vertex the refinement adds takes a per-vertex value from its edge's two corners.
enum class RefinedRule {
    Mean,        // each component (a + b) / 2, in double, rounded to float: positions, deltas, UVs, colours
    UnitNormal,  // (a + b) normalised in double; where the corners cancel (a knife edge), a's own
    Tangent,     // xyz as UnitNormal, w (the handedness) a's
};

// The value halfway along the edge (a, b), `components` floats each (3 for UnitNormal, 4 for
// Tangent), into `out`: the one rule for the scene's data and for asset.glb's attributes.
void refinedValue(const float* a, const float* b, float* out, size_t components, RefinedRule rule);

// Extends `values` (the instance's own vertices first, `components` floats each) with one value
// for every vertex the refinement added, in order: vertex own + j is halfway along refinedFrom[j],
// whose corners are earlier vertices (own or added).
void appendRefinedValues(std::vector<float>& values, size_t components,
                         const std::vector<std::pair<uint32_t, uint32_t>>& refinedFrom, RefinedRule rule);

struct RefinementReport {
    size_t trianglesBefore = 0, trianglesAfter = 0;
    size_t verticesBefore = 0, verticesAfter = 0;
};

// Refines `scene` in place (its instances, vertex and triangle arrays) and re-places every
// instance with what it was last placed with. maxEdge > 0.
RefinementReport refineMesh(Scene& scene, double maxEdge);
// The same, counting the triangles as it makes them: nothing is changed, and nullopt returned, as
// soon as more than `triangleLimit` would be made (the exact count, where estimatedRefinedTriangles
// only guesses: longest-edge bisection makes up to four times its estimate).
std::optional<RefinementReport> refineMesh(Scene& scene, double maxEdge, size_t triangleLimit);

// Splits every edge of every mesh once, at its midpoint (a triangle becomes four, by the same
// bisection): a sampling mesh with samples on every triangle for the least-squares vertex fit
// (lib/estimate/vertex_fit.h), whose vertices are the mesh's own, in their order, then one per
// edge. Each added vertex's refinedFrom names two of the mesh's own vertices.
RefinementReport bisectEveryEdge(Scene& scene);

// What refineMeshWhere follows the mesh through: every vertex's world position in each of some
// poses (poses[k][v], scene order; the refinement gives a new vertex its edge's midpoint in each),
// and each triangle's piece of surface (MeshTopology::edgeConnectedPieces; its pieces inherit it).
struct RefinementTracks {
    std::vector<std::vector<Vec3f>> poses;
    std::vector<uint32_t> pieces;
};

// An edge refineMeshWhere asks about: of scene instance `instance`, its triangles of `piece`, its
// `length` in the current pose, and its corners' world positions in each tracked pose (a[k], b[k]:
// the corners in the order of their places in the current pose, so that both its triangles, and
// both sides of a seam, ask with the same floats).
struct EdgeToSplit {
    size_t instance;
    uint32_t piece;
    double length;
    const std::vector<Vec3f>& a;
    const std::vector<Vec3f>& b;
};
// Whether an edge must be split: a pure function of the edge, so that both triangles of an edge
// agree and the refined mesh is conforming. It must say no to every edge short enough.
using EdgeSplitTest = std::function<bool(const EdgeToSplit&)>;

// Longest-edge bisection as refineMesh, splitting an edge when `needs` says (each triangle splits
// the longest of its edges that need it). Nothing is changed, and nullopt returned, when more
// than `triangleLimit` triangles would be made.
std::optional<RefinementReport> refineMeshWhere(Scene& scene, const RefinementTracks& tracks, const EdgeSplitTest& needs,
                                                size_t triangleLimit);

// About how many triangles refineMesh(scene, maxEdge) makes (each triangle as (longest edge /
// maxEdge)² pieces; bisection makes up to four times that): what a run checks first, so that a
// LENGTH far too small is refused at once; the limited refineMesh then holds the exact count to
// the limit.
size_t estimatedRefinedTriangles(const Scene& scene, double maxEdge);

}  // namespace qsgi
