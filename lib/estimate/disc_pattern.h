// The fixed cell pattern of a vertex's disc (docs/design.md §5): kRings rings of equal area × kSectors
// sectors in a tangent frame derived from n_v alone. The sector count is even, so the pattern is
// symmetric under a half turn and its first moments vanish exactly. Coordinates here are in units
// of the radius r: the unit disc.
#pragma once

#include <array>
#include <cstdint>

#include "util/vecmath.h"

namespace qsgi {

constexpr int kDiscRings = 16;
constexpr int kDiscSectors = 16;
constexpr int kDiscCells = kDiscRings * kDiscSectors;
static_assert(kDiscSectors % 2 == 0, "a half turn must map the pattern onto itself");

// A set of cells, one bit each.
struct CellMask {
    std::array<uint64_t, kDiscCells / 64> words{};
    void set(int cell) { words[cell >> 6] |= uint64_t(1) << (cell & 63); }
    bool test(int cell) const { return (words[cell >> 6] >> (cell & 63)) & 1u; }
    int count() const;
    bool operator==(const CellMask& o) const { return words == o.words; }
};

// Cell index ring·kDiscSectors + sector of the point (x, y) of the unit disc (points on or just
// past the rim fall in the outer ring).
int discCellOf(double x, double y);
// Ring of a cell, and its centre (the centre of its polar rectangle) on the unit disc.
inline int discRingOf(int cell) { return cell / kDiscSectors; }
void discCellCentre(int cell, double& x, double& y);

// The points of the pattern that reachability tests aim at (docs/design.md §5), on the unit disc: the
// cells' shared corners (ring boundaries × sector boundaries, ring boundary 0 being v), each
// cell's centre, and each cell's 4×4 sub-points. Worked out once: every disc tests the same ones.
struct DiscPatternPoints {
    struct Point {
        double x, y;
    };
    std::array<Point, size_t(kDiscRings + 1) * kDiscSectors> corners;  // [ring boundary · sectors + sector]
    std::array<Point, kDiscCells> centres;                             // discCellCentre
    std::array<std::array<Point, 16>, kDiscCells> subPoints;           // [cell][4 · ring step + sector step]
};
const DiscPatternPoints& discPatternPoints();

// Exact integrals over one cell of the unit disc: ∫1, ∫x, ∫y, ∫x², ∫xy, ∫y².
struct CellMoments {
    double m0, mx, my, mxx, mxy, myy;
};
const CellMoments& discCellMoments(int cell);

// Fixed tangent frame of a normal (the same for every caller, so cells mean the same everywhere).
inline void discFrame(const Vec3f& normal, Vec3f& tangent, Vec3f& bitangent) { orthonormalBasis(normal, tangent, bitangent); }

// Area of the part of the disc of radius s (units of r, 0 < s ≤ 1) that is covered, given the
// covered share (0…1) of each ring, each ring taken as uniformly covered.
double discAreaWithin(const std::array<double, kDiscRings>& ringShare, double s);

}  // namespace qsgi
