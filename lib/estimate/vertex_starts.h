// Where each vertex's shadow and gather rays leave from, and along which normal (docs/design.md
// §5.1, issue 56): the vertex itself, as close as floating point allows. The start is
//   s_v = v + δ_v n_v (+ 2 δ_v out of the front of a wall of v's own mesh standing on v;
//         + 16 δ_v over v's triangles at a border),
// where δ_v is set by the float error of v's coordinates and its incident triangles' size —
// the geometry's own scale, never the photon radius nor the scene's diagonal — so s_v sees what
// the point v sees: a direction into the back of v's own surface meets one of v's triangles at
// once and is blocked, a crease's other wall blocks what it blocks at v, and a part lying a hair
// above v (a strap on a shell, a plate on a floor) covers v. Only where s_v would lie inside
// other geometry (a floor vertex on the foot line of a block, which rounding may put a hair
// inside it) does the start step sideways, by 2δ_v, to the open side.
//
// It owns the rule and keeps it current across moves: a vertex's start depends on the geometry
// within kReachOffsets δ_v of v (its incident triangles, the step and the short probes of the
// inside test), so after a pose only the moved vertices and those that near to a moved part's old or new
// bounds are looked at again, with the same function: an update gives what a from-scratch
// computation of the pose gives, to the bit.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/scene.h"
#include "trace/scene_bvh.h"

namespace qsgi {

class MeshTopology;

// One vertex's start: the point, the offset δ_v it was made with, and the height under which
// a surface in front of v covers it (FinalGather's covered-vertex rule): a quarter of v's
// longest incident edge, what v's own mesh cannot resolve (at an output vertex in a sampling mesh,
// of its edge on the output mesh: Scene::coverEdges).
struct VertexStart {
    Vec3f point{0.0f};
    float offset = 0;
    float coverHeight = 0;
};

// The longest edge of the triangles at v's position (welded), in the current pose: the size of
// surface detail v's mesh resolves, of which the cover height is a quarter.
double longestIncidentEdge(const Scene& scene, const MeshTopology& topology, uint32_t v);

// The rule for vertex v in the scene's current pose (bvh holds it). frontNormals:
// Scene::frontFaceNormals(). Depends on nothing but the geometry within kReachOffsets·offset of v.
VertexStart vertexRayStart(const Scene& scene, const SceneBvh& bvh, const MeshTopology& topology,
                           const std::vector<Vec3f>& frontNormals, uint32_t v);

class VertexStarts {
public:
    // How far from v, in units of its offset δ_v, the geometry its start depends on may lie:
    // the lift and the steps (at most 21 δ_v together) and the inside test's probes (4 δ_v from
    // there).
    static constexpr float kReachOffsets = 26;

    // Every vertex, for the scene's current pose (bvh holds it).
    void computeAll(const Scene& scene, const SceneBvh& bvh);
    // After a pose change: the vertices that moved (vertexMoved) or whose reach meets one of
    // `movedBounds` (old and new bounds of each moved part) are computed again. Returns those whose
    // start or normal changed, increasing.
    std::vector<uint32_t> update(const Scene& scene, const SceneBvh& bvh, const std::vector<Bounds3f>& movedBounds,
                                 const std::vector<uint8_t>& vertexMoved);

    const Vec3f& point(uint32_t v) const { return starts_[v].point; }
    const Vec3f& normal(uint32_t v) const { return normals_[v]; }
    float coverHeight(uint32_t v) const { return starts_[v].coverHeight; }
    size_t size() const { return starts_.size(); }
    size_t bytes() const { return starts_.capacity() * sizeof(VertexStart) + normals_.capacity() * sizeof(Vec3f); }

private:
    std::vector<VertexStart> starts_;
    std::vector<Vec3f> normals_;
};

}  // namespace qsgi
