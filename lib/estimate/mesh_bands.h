// Where on a mesh a place lies, for scoring accuracy by band (docs/method.md, `qsgi compare`): near an
// edge of its surface. One rule for the vertices of a vertex reference and the points of a surface
// reference (estimate/accuracy.h, estimate/surface_accuracy.h); near another surface is asked of a
// TriangleGrid (scene/triangle_grid.h) and MeshTopology::edgeConnectedPieces.
// Vertices are welded by exact position throughout (MeshTopology), so a UV or normal seam is no edge.
#pragma once

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "estimate/point_index.h"
#include "scene/mesh_topology.h"
#include "scene/scene.h"

namespace qsgi {

// The edges of a mesh's surfaces — an edge used by one triangle, by more than two, or by two
// whose front faces turn by more than the own surface's 45° — and how far a place is from them.
class MeshEdges {
public:
    // radius: the distance within() answers for (exact to radius/16, see the .cpp).
    MeshEdges(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals, const std::vector<Triangle>& triangles,
              const MeshTopology& topology, float radius);
    // Vertex v (welded) lies on an edge.
    bool vertexOnEdge(uint32_t v) const { return onEdge_[topology_.weldedId(v)] != 0; }
    // p lies within the radius of an edge.
    bool within(const Vec3f& p) const;

private:
    float squaredDistanceToPiece(const Vec3f& p, size_t piece) const;

    const MeshTopology& topology_;
    float radius_, reach_ = 0;
    std::vector<uint8_t> onEdge_;
    std::vector<std::pair<Vec3f, Vec3f>> pieces_;
    std::vector<Vec3f> midpoints_;
    std::optional<PointIndex> index_;
};

}  // namespace qsgi
