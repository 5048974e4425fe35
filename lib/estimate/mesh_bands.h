// Where on a mesh a place lies, for scoring accuracy by band (docs/method.md, `qsgi compare`): near an
// edge of its surface, or near another surface. One set of rules for the vertices of a vertex
// reference and the points of a surface reference (estimate/accuracy.h, estimate/surface_accuracy.h).
// Vertices are welded by exact position throughout (MeshTopology), so a UV or normal seam is no edge.
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
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

// A mesh's triangles in a uniform grid of cells about a mean triangle across, each cell listing
// the triangles whose bounds, padded by `reach`, overlap it: the triangles that may lie within
// `reach` of a place are those of its cell.
class TriangleGrid {
public:
    TriangleGrid(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, float reach);
    // The triangles listed in p's cell (none outside the grid), in increasing order.
    const std::vector<uint32_t>& near(const Vec3d& p) const;

private:
    uint64_t key(const Vec3d& p) const;
    Bounds3f bounds_;
    double cell_ = 1;
    std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
    std::vector<uint32_t> none_;
};

// Squared distance from p to the triangle abc (closest point by regions, Ericson §5.1.5).
double squaredDistanceToTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

// Each triangle's piece of surface joined across shared edges (welded), whatever their crease:
// named by the piece's smallest triangle index. A block standing on a floor, a panel under a
// ceiling and a character's foot are pieces of their own even where a corner meets a floor vertex.
std::vector<uint32_t> edgeConnectedPieces(const std::vector<Triangle>& triangles, const MeshTopology& topology);

}  // namespace qsgi
