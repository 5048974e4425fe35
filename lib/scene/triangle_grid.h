// A mesh's triangles in a uniform grid, to find those near a place, and the exact distance to one:
// what scoring by band (estimate/mesh_bands.h, estimate/surface_accuracy.h), the accuracy tool's
// contact test and the contact refinement (scene/contact_refinement.h) ask.
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

// The grid's cells are about a mean triangle across; each lists the triangles whose bounds, padded
// by `reach`, overlap it: the triangles that may lie within `reach` of a place are those of its cell.
class TriangleGrid {
public:
    // `only`, if given: the triangles to list (others are left out), by index.
    TriangleGrid(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, float reach,
                 const std::vector<uint8_t>& only = {});
    // The triangles listed in p's cell (none outside the grid), in increasing order.
    const std::vector<uint32_t>& near(const Vec3d& p) const;
    bool empty() const { return cells_.empty(); }

private:
    uint64_t key(const Vec3d& p) const;
    Bounds3f bounds_;
    double cell_ = 1;
    std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
    std::vector<uint32_t> none_;
};

// Squared distance from p to the triangle abc (closest point by regions, Ericson §5.1.5).
double squaredDistanceToTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace qsgi
