// Bounds over the scene's triangles that let the own-surface search stop early (docs/design.md §5,
// the own surface's cost). On a dense mesh a vertex's own surface holds hundreds of triangles
// within r, and walking them all to find the highest is what made start points cost 25–190 µs a
// vertex. But ε_v⁺ is a whole number of scene epsilons (own_surface.h), and almost everywhere —
// flat and convex surfaces — it is just the height its incident triangles give. A superset of
// the own surface (every triangle near v that faces within 45° of n_v, connected or not) that
// rises no higher proves it; this tree answers that question by descending only where a node's
// bounds say a triangle might rise, so its cost follows what is near v, not the mesh density.
// The disc regions ask it the same kind of question for their static shortcut (any static
// triangle near v rising to their rays' height), where Embree's point query visits every
// triangle near and gave up on dense meshes.
//
// Only v's own piece of surface can hold its own surface: the triangles joined to v through
// shared (welded) vertices. Each triangle's piece is numbered, so a light panel hung under a
// ceiling or a block standing on a floor — other pieces — never makes the walk run.
//
// A binary tree over the triangles in Morton order of their centroids, eight to a leaf. Each
// node bounds its triangles' corners twice — an axis-aligned box, and a slab along the node's
// mean front normal inside a ball, which stays tight on tilted planes where the box does not —
// and their front normals by a box. Every bound is conservative: a triangle the tree skips
// could not have been reported.
#pragma once

#include <cstdint>
#include <vector>

#include "scene/mesh_topology.h"
#include "scene/scene.h"

namespace qsgi {

class OwnSurfaceTree {
public:
    // frontNormals: Scene::frontFaceNormals(), for the scene's current pose; topology: its welding.
    OwnSurfaceTree(const Scene& scene, const std::vector<Vec3f>& frontNormals, const MeshTopology& topology);

    // The piece of surface vertex v belongs to (triangles joined through welded vertices).
    uint32_t pieceOfVertex(uint32_t v) const { return vertexPiece_[v]; }
    // For anyRising: triangles of every piece.
    static constexpr uint32_t kAnyPiece = UINT32_MAX;

    // Calls visit(triangle) for every triangle of `piece` (or of any, kAnyPiece) that may (a) have a front normal whose
    // dot with `normal` exceeds `minNormalDot`, (b) come within `reach` of `centre`, and (c) have
    // a corner at `height` or more above `centre` along `normal` — and for some others besides
    // (the bounds are conservative). Stops, returning true, as soon as visit returns true.
    template <typename Visit>
    bool anyRising(uint32_t piece, const Vec3d& centre, const Vec3d& normal, double minNormalDot, double reach,
                   double height, Visit&& visit) const;

    size_t nodeCount() const { return nodes_.size(); }

private:
    struct Node {
        Bounds3f box;        // corners
        Bounds3f normals;    // front normals
        Vec3d axis{0.0};     // unit: the slab's direction
        double slabLo = 0, slabHi = 0;  // axis · corner over the node's corners
        Vec3d centre{0.0};   // the box's centre
        double radius = 0;   // no corner farther from `centre`
        uint32_t begin = 0, end = 0;    // triangles order_[begin, end)
        uint32_t left = 0, right = 0;  // children; 0: a leaf
        uint32_t piece = kMixed;       // the piece all its triangles belong to, or kMixed
    };
    static constexpr uint32_t kMixed = UINT32_MAX;
    uint32_t build(uint32_t begin, uint32_t end, const Scene& scene, const std::vector<Vec3f>& frontNormals);
    // Largest direction · p over the node's corners p, or more: by the slab and ball, and by both.
    static double slabMaxDot(const Node& node, const Vec3d& direction);
    static double maxDot(const Node& node, const Vec3d& direction);
    bool mayRise(const Node& node, const Vec3d& centre, const Vec3d& normal, double minNormalDot, double reach,
                 double height) const;

    std::vector<uint32_t> order_;  // triangles in Morton order
    std::vector<Node> nodes_;      // nodes_[0]: the root
    std::vector<uint32_t> trianglePiece_, vertexPiece_;
};

template <typename Visit>
bool OwnSurfaceTree::anyRising(uint32_t piece, const Vec3d& centre, const Vec3d& normal, double minNormalDot,
                               double reach, double height, Visit&& visit) const {
    if (nodes_.empty()) return false;
    uint32_t stack[64];
    int depth = 0;
    stack[depth++] = 0;
    while (depth > 0) {
        const Node& node = nodes_[stack[--depth]];
        if (piece != kAnyPiece && node.piece != kMixed && node.piece != piece) continue;
        if (!mayRise(node, centre, normal, minNormalDot, reach, height)) continue;
        if (node.left == 0) {
            for (uint32_t i = node.begin; i < node.end; ++i)
                if ((piece == kAnyPiece || trianglePiece_[order_[i]] == piece) && visit(order_[i])) return true;
        } else {
            stack[depth++] = node.right;
            stack[depth++] = node.left;
        }
    }
    return false;
}

}  // namespace qsgi
