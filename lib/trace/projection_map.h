// Projection maps (photon-mapping practice; issue 12): where a light's photons can reach
// something that counts, so that emission spends no photon on directions that meet nothing.
//
// A map covers a light's domain — the directions of a point or spot light, the plane a
// directional light crosses — parameterised by the unit square so that equal squares have equal
// measure (solid angle or area). The square is refined as a quadtree down to `depth`; a cell is
// kept while any target may overlap it, tested against a bound of the cell that contains
// all of it, so the map is conservative: a cell that might reach geometry is kept however thin
// the geometry in it (nothing is probed by rays). Photons choose a kept cell uniformly and a
// point uniformly in it; each carries the light's power over the measure actually sampled, so
// the estimate is unbiased.
//
// Targets are the static triangles, the discs DETP counts a light's photons on, and the box each
// moving instance sweeps over the whole animation, dilated by the disc radius: the same map
// serves every frame, and incremental and full recomputation emit the same photons. Cells are
// tested against them exactly (a triangle is a spherical triangle seen from a point light),
// only the cells' bounds are loose.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "scene/scene.h"

namespace qsgi {

// The points within `radius` of the triangle (corner[0], corner[1], corner[2]); a segment or a
// point when corners coincide.
struct Target {
    Vec3d corner[3];
    double radius;
};

// What a light's first segments can count on: each static triangle (dilated by `epsilon`); the
// disc of radius discRadius (DETP's; 0 for estimators that count impacts only) of each static
// vertex whose front faces the light — DETP counts a crossing only from the front (d·n_v < 0),
// and every point of a disc sees a point light from the same side — as thin strips that follow
// the disc's outline seen from the light (a disc seen edge-on covers a sliver, not its circle);
// and the moving instances' swept boxes dilated by discRadius + epsilon (their normals change).
// lightDirectionAt(q): the unit direction photons travel from the light to q.
std::vector<Target> mapTargets(const Scene& scene, double epsilon, double discRadius,
                               const std::function<Vec3d(const Vec3d&)>& lightDirectionAt);

// A map over the unit square: the kept cells at the finest level, row-major order.
class ProjectionMap {
public:
    ProjectionMap() = default;
    // mayOverlap(x0, y0, x1, y1) returns a test of the square [x0, x1] × [y0, y1]: called with
    // a target's index, whether the target may meet the part of the domain the square maps to
    // (false only if it certainly does not). The square's own bounds are worked out once. Defined, and
    // instantiated, in projection_map.cpp: directionMap and footprintMap make every map.
    template <class MayOverlap>
    ProjectionMap(int depth, const std::vector<Target>& targets, const MayOverlap& mayOverlap);

    bool empty() const { return cells_.empty(); }
    size_t keptCells() const { return cells_.size(); }
    size_t allCells() const { return size_t(1) << (2 * depth_); }
    // Fraction of the domain's measure kept.
    double keptFraction() const { return double(keptCells()) / double(allCells()); }
    // A point of the unit square, uniform over the kept cells: uCell chooses the cell, (u0, u1)
    // the point in it.
    void sample(float uCell, float u0, float u1, double& x, double& y) const;
    // The same from a stratified pair (u, v): the kept cells laid end to end in row-major order
    // cover u's range in equal parts, u's place within its part is the column coordinate in the
    // cell and v the row coordinate. Points stratified in (u, v) stay stratified over the cells
    // and within each.
    void sampleStratified(double u, float v, double& x, double& y) const;

private:
    // The point (u, v) of the unit square inside kept cell k.
    void pointInCell(size_t k, double u, double v, double& x, double& y) const;

    int depth_ = 0;
    std::vector<uint32_t> cells_;  // (row << depth) | column, increasing
};

// The direction at polar angle θ (given as cos θ, sin θ) and azimuth φ about unit `axis`, with
// t, b = orthonormalBasis(axis): uniformCone's parameterisation, which direction maps use.
inline Vec3d coneDirection(const Vec3d& axis, const Vec3d& t, const Vec3d& b, double cosTheta, double sinTheta, double phi) {
    return t * (sinTheta * std::cos(phi)) + b * (sinTheta * std::sin(phi)) + axis * cosTheta;
}

// The map of a point or spot light at `apex` over the cone of directions about unit `axis` with
// cos half-angle cosMax (−1: every direction), with the parameterisation uniformCone uses.
// extraCone: a second cone (a spot light's own, when the domain is the cone around the scene)
// that a kept cell must also meet; cosExtra = −1 for none.
ProjectionMap directionMap(const Vec3d& apex, const Vec3d& axis, double cosMax, const Vec3d& extraAxis, double cosExtra,
                           const std::vector<Target>& targets, int depth);

// The map of a directional light over the square of half-size `halfSize` centred on `centre`,
// in the plane perpendicular to unit `direction`, with orthonormalBasis(direction)'s axes.
ProjectionMap footprintMap(const Vec3d& centre, const Vec3d& direction, double halfSize,
                           const std::vector<Target>& targets, int depth);

}  // namespace qsgi
