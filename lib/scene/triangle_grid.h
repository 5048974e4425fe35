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
// by `reach`, overlap it: the triangles that may lie within `reach` of a place are those of its
// cell. A triangle whose padded bounds span more than kMostCells cells (a ramp across a scene of
// small parts) is kept on one list that every place is given instead, so no triangle fills the
// grid.
class TriangleGrid {
public:
    static constexpr uint64_t kMostCells = 4096;
    // `only`, if given: the triangles to list (others are left out), by index.
    TriangleGrid(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, float reach,
                 const std::vector<uint8_t>& only = {});
    // Calls visit(t) for every triangle that may lie within `reach` of p — those of p's cell, in
    // increasing order, then the large ones; none for a place outside the padded bounds (or not
    // finite) — until a call returns true; returns whether one did.
    template <typename Visit>
    bool anyNear(const Vec3d& p, Visit&& visit) const {
        if (!inside(p)) return false;
        if (const auto it = cells_.find(key(p)); it != cells_.end())
            for (uint32_t t : it->second)
                if (visit(t)) return true;
        for (uint32_t t : large_)
            if (visit(t)) return true;
        return false;
    }
    bool empty() const { return cells_.empty() && large_.empty(); }

private:
    bool inside(const Vec3d& p) const;
    uint64_t key(const Vec3d& p) const;
    Bounds3f bounds_;  // of the listed triangles, padded by reach
    double cell_ = 1;
    std::unordered_map<uint64_t, std::vector<uint32_t>> cells_;
    std::vector<uint32_t> large_;
};

// Squared distance from p to the triangle abc (closest point by regions, Ericson §5.1.5).
double squaredDistanceToTriangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace qsgi
