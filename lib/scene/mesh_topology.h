// Which triangles meet at each vertex, with vertices welded by exact position, so that a UV or
// normal seam (two vertices at one place) does not cut a surface in two (docs/design.md §5, own surface).
// Built from plain arrays, so the scene and a PLY read back (qsgi compare) use the same rules.
#pragma once

#include <cstdint>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

struct Triangle;
struct Scene;

class MeshTopology {
public:
    // Vertices from `sideFrom` on weld only among themselves: a scene's back sides
    // (lib/scene/back_sides.h) lie where their fronts do, but are surfaces of their own.
    MeshTopology(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles,
                 uint32_t sideFrom = 0xFFFFFFFFu);
    // The scene's: its back sides apart from their fronts.
    explicit MeshTopology(const Scene& scene);

    // The smallest vertex index at v's position: equal for welded vertices.
    uint32_t weldedId(uint32_t v) const { return welded_[v]; }
    // Triangles that have a vertex at v's position, in increasing order.
    const uint32_t* trianglesBegin(uint32_t v) const { return &incident_[first_[welded_[v]]]; }
    const uint32_t* trianglesEnd(uint32_t v) const { return &incident_[first_[welded_[v] + 1]]; }
    // Each vertex's piece of surface: the vertices joined to it through triangles and welds, named
    // by the piece's smallest vertex index, so the numbering depends on the geometry alone.
    std::vector<uint32_t> vertexPieces(const std::vector<Triangle>& triangles) const;
    // Each triangle's piece of surface joined across edges (welded) that exactly two triangles use,
    // whatever their crease, named by the piece's smallest triangle index: a block standing on a
    // floor, a panel under a ceiling and a character's foot are pieces of their own even where a
    // corner meets a floor vertex or a foot runs along a row of floor edges (used by three); a
    // box's walls are one.
    std::vector<uint32_t> edgeConnectedPieces(const std::vector<Triangle>& triangles) const;

private:
    std::vector<uint32_t> welded_;
    std::vector<uint32_t> first_;     // CSR offsets by welded id (only welded ids have entries)
    std::vector<uint32_t> incident_;  // triangle indices
};

}  // namespace qsgi
