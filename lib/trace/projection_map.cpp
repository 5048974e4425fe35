#include "trace/projection_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace qsgi {

namespace {

// Angles are compared in double; the float directions photons take differ from the double ones
// by ~1e-7 rad. This slack keeps every cell they can fall in.
constexpr double kAngleSlack = 1e-6;

double angleBetween(const Vec3d& a, const Vec3d& b) { return std::acos(std::clamp(dot(a, b), -1.0, 1.0)); }

double distanceToSegment(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d ab = b - a;
    const double len2 = dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return length(a + ab * t - p);
}

double distanceToTriangle(const Vec3d& p, const Vec3d (&c)[3]) {
    const Vec3d n = cross(c[1] - c[0], c[2] - c[0]);
    const double len = length(n);
    if (len > 0) {
        const Vec3d u = n * (1.0 / len);
        const double h = dot(p - c[0], u);
        const Vec3d q = p - u * h;  // in the plane
        bool inside = true;
        for (int i = 0; i < 3; ++i) inside &= dot(cross(c[(i + 1) % 3] - c[i], q - c[i]), u) >= 0;
        if (inside) return std::abs(h);
    }
    return std::min({distanceToSegment(p, c[0], c[1]), distanceToSegment(p, c[1], c[2]), distanceToSegment(p, c[2], c[0])});
}

// Distance in the plane from the segment (ax, ay)–(bx, by) to the rectangle [x0, x1] × [y0, y1].
double segmentToRectangle(double ax, double ay, double bx, double by, double x0, double y0, double x1, double y1) {
    // Liang–Barsky: 0 if any part of the segment lies in the rectangle.
    double t0 = 0, t1 = 1;
    const double dx = bx - ax, dy = by - ay;
    auto clip = [&](double p, double q) {
        if (p == 0) return q >= 0;
        const double r = q / p;
        if (p < 0) t0 = std::max(t0, r);
        else t1 = std::min(t1, r);
        return t0 <= t1;
    };
    if (clip(-dx, ax - x0) && clip(dx, x1 - ax) && clip(-dy, ay - y0) && clip(dy, y1 - ay)) return 0;
    auto pointToRectangle = [&](double px, double py) {
        return std::hypot(std::max({x0 - px, 0.0, px - x1}), std::max({y0 - py, 0.0, py - y1}));
    };
    auto cornerToSegment = [&](double px, double py) {
        return distanceToSegment(Vec3d(px, py, 0), Vec3d(ax, ay, 0), Vec3d(bx, by, 0));
    };
    return std::min({pointToRectangle(ax, ay), pointToRectangle(bx, by), cornerToSegment(x0, y0), cornerToSegment(x1, y0),
                     cornerToSegment(x0, y1), cornerToSegment(x1, y1)});
}

// The strips that hold the disc of radius r about v with unit normal n, seen along unit
// direction `view`: strips across its widest axis s (⊥ n and view), each a segment along the
// in-plane axis w ⊥ s dilated by the strip's half-width. Seen from the light they widen the
// disc's outline by that half-width only, where its circle would widen it by r.
void addDisc(const Vec3d& v, const Vec3d& n, double r, const Vec3d& view, double epsilon, std::vector<Target>& out) {
    constexpr int kStrips = 4;
    const Vec3d across = cross(n, view);
    const double len = length(across);
    if (!(len > 1e-3)) {  // seen face-on: its outline is its circle
        out.push_back({{v, v, v}, r + epsilon});
        return;
    }
    const Vec3d s = across * (1.0 / len), w = cross(n, s);
    for (int i = 0; i < kStrips; ++i) {
        const double s0 = r * (-1 + 2.0 * i / kStrips), s1 = r * (-1 + 2.0 * (i + 1) / kStrips);
        const double nearest = s0 < 0 && s1 > 0 ? 0.0 : std::min(std::abs(s0), std::abs(s1));
        const double halfLength = std::sqrt(std::max(0.0, r * r - nearest * nearest));
        const Vec3d middle = v + s * (0.5 * (s0 + s1));
        out.push_back({{middle - w * halfLength, middle + w * halfLength, middle + w * halfLength}, 0.5 * (s1 - s0) + epsilon});
    }
}

void addBox(const Bounds3f& box, double margin, std::vector<Target>& out) {
    auto corner = [&](int i) {
        return Vec3d(i & 1 ? box.upper.x : box.lower.x, i & 2 ? box.upper.y : box.lower.y, i & 4 ? box.upper.z : box.lower.z);
    };
    // Two triangles per face, corners by bit pattern (x = 1, y = 2, z = 4).
    static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    for (const auto& f : kFaces) {
        out.push_back({{corner(f[0]), corner(f[1]), corner(f[2])}, margin});
        out.push_back({{corner(f[0]), corner(f[2]), corner(f[3])}, margin});
    }
}

// The indices of `candidates` that keep(i) accepts, in order; in parallel when there are many.
template <class Keep>
std::vector<uint32_t> filterCandidates(const std::vector<uint32_t>& candidates, const Keep& keep) {
    constexpr size_t kChunk = 16384;
    const size_t chunks = (candidates.size() + kChunk - 1) / kChunk;
    std::vector<std::vector<uint32_t>> parts(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        for (size_t k = c * kChunk; k < std::min(candidates.size(), (c + 1) * kChunk); ++k)
            if (keep(candidates[k])) parts[c].push_back(candidates[k]);
    });
    std::vector<uint32_t> kept;
    for (const auto& p : parts) kept.insert(kept.end(), p.begin(), p.end());
    return kept;
}

}  // namespace

std::vector<Target> mapTargets(const Scene& scene, double epsilon, double discRadius,
                               const std::function<Vec3d(const Vec3d&)>& lightDirectionAt) {
    std::vector<Target> targets;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        if (scene.triangleDynamic[t]) continue;  // inside its instance's swept box
        const Triangle& tri = scene.triangles[t];
        targets.push_back({{Vec3d(scene.positions[tri.v[0]]), Vec3d(scene.positions[tri.v[1]]),
                            Vec3d(scene.positions[tri.v[2]])},
                           epsilon});
    }
    if (discRadius > 0)
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            if (scene.vertexDynamic[v]) continue;
            const Vec3d p = Vec3d(scene.positions[v]), n = Vec3d(scene.normals[v]);
            const Vec3d view = lightDirectionAt(p);
            // Crossed from the front only (d·n < 0); the tolerance keeps grazing discs.
            if (dot(view, n) < 1e-6) addDisc(p, n, discRadius, view, epsilon, targets);
        }
    for (const Bounds3f& b : scene.sweptBoxes)
        if (!b.empty()) addBox(b, discRadius + epsilon, targets);
    return targets;
}

template <class MayOverlap>
ProjectionMap::ProjectionMap(int depth, const std::vector<Target>& targets, const MayOverlap& mayOverlap)
    : depth_(depth) {
    // Level by level, top-down: each cell tests only the targets its parent kept, and a cell no
    // target may meet is dropped with all its children. Kept cells are sorted at the end, so the
    // map (and every photon's cell) does not depend on the threads.
    struct Cell {
        uint32_t row, column, parent;  // parent: into the previous level's lists
    };
    std::vector<Cell> level{{0, 0, 0}};
    std::vector<std::vector<uint32_t>> parentNear(1, std::vector<uint32_t>(targets.size()));
    std::iota(parentNear[0].begin(), parentNear[0].end(), 0u);
    for (int l = 0;; ++l) {
        const double size = std::ldexp(1.0, -l);
        std::vector<std::vector<uint32_t>> near(level.size());
        tbb::parallel_for(size_t(0), level.size(), [&](size_t i) {
            const Cell& c = level[i];
            const double x0 = c.column * size, y0 = c.row * size;
            const auto keep = mayOverlap(x0, y0, x0 + size, y0 + size);
            const std::vector<uint32_t>& candidates = parentNear[c.parent];
            if (l < depth) near[i] = filterCandidates(candidates, keep);
            else if (std::any_of(candidates.begin(), candidates.end(), keep)) near[i].push_back(0);
        });
        if (l == depth) {
            for (size_t i = 0; i < level.size(); ++i)
                if (!near[i].empty()) cells_.push_back((level[i].row << depth) | level[i].column);
            break;
        }
        std::vector<Cell> next;
        for (size_t i = 0; i < level.size(); ++i)
            if (!near[i].empty())
                for (uint32_t child = 0; child < 4; ++child)
                    next.push_back({2 * level[i].row + (child >> 1), 2 * level[i].column + (child & 1), uint32_t(i)});
        level.swap(next);
        parentNear.swap(near);
        if (level.empty()) break;
    }
    std::sort(cells_.begin(), cells_.end());
}

void ProjectionMap::sample(float uCell, float u0, float u1, double& x, double& y) const {
    const size_t k = std::min(cells_.size() - 1, size_t(double(uCell) * double(cells_.size())));
    pointInCell(k, double(u0), double(u1), x, y);
}

void ProjectionMap::pointInCell(size_t k, double u, double v, double& x, double& y) const {
    const uint32_t cell = cells_[k];
    const uint32_t row = cell >> depth_, column = cell & ((1u << depth_) - 1);
    const double size = std::ldexp(1.0, -depth_);
    x = (column + u) * size;
    y = (row + v) * size;
}

void ProjectionMap::sampleStratified(double u, float v, double& x, double& y) const {
    const double scaled = u * double(cells_.size());  // exact: u has 32 bits, the cell count at most 2^(2·depth)
    const size_t k = std::min(cells_.size() - 1, size_t(scaled));
    pointInCell(k, scaled - double(k), double(v), x, y);
}

ProjectionMap directionMap(const Vec3d& apex, const Vec3d& axis, double cosMax, const Vec3d& extraAxis, double cosExtra,
                           const std::vector<Target>& targets, int depth) {
    // Each target as seen from the apex: a spherical triangle (its corners' directions, the unit
    // normals of its edges' great circles, its orientation), and the angle its dilation adds at
    // its nearest point; or "around the apex".
    struct Seen {
        Vec3d corner[3], edgeNormal[3], edgeCross[3];  // edgeCross: corner k × corner k+1
        bool edgeIsArc[3] = {false, false, false};
        double orientation = 0;  // sign of det(corners); 0: degenerate (a segment, a point, or edge-on)
        double angularRadius = 0;
        bool surroundsApex = false;
    };
    std::vector<Seen> seen(targets.size());
    tbb::parallel_for(size_t(0), targets.size(), [&](size_t i) {
        const Target& t = targets[i];
        Seen& s = seen[i];
        const double nearest = distanceToTriangle(apex, t.corner);
        s.surroundsApex = !(nearest > t.radius);
        if (s.surroundsApex) return;
        s.angularRadius = std::asin(std::min(1.0, t.radius / nearest));
        for (int k = 0; k < 3; ++k) s.corner[k] = normalize(t.corner[k] - apex);
        for (int k = 0; k < 3; ++k) {
            const Vec3d n = cross(s.corner[k], s.corner[(k + 1) % 3]);
            s.edgeCross[k] = n;
            s.edgeIsArc[k] = length(n) >= 1e-12;
            if (s.edgeIsArc[k]) s.edgeNormal[k] = n * (1.0 / length(n));
            // Corners on opposite sides of the apex on one line: the edge passes beside it at
            // `nearest`; keep every direction rather than guess the arc.
            else if (dot(s.corner[k], s.corner[(k + 1) % 3]) < 0) s.surroundsApex = true;
        }
        const double det = dot(s.corner[0], cross(s.corner[1], s.corner[2]));
        s.orientation = std::abs(det) > 1e-15 ? (det > 0 ? 1.0 : -1.0) : 0.0;
    });
    // Whether some direction of target s lies within angle `reach` of unit u: inside the
    // spherical triangle, or within reach of a corner or an edge's arc. Compared through cosines
    // and sines (cos(reach), sin(reach) given), so no test calls a transcendental function.
    auto within = [](const Seen& s, const Vec3d& u, double cosReach, double sinReach) {
        if (s.orientation != 0) {
            bool inside = true;
            for (int k = 0; k < 3; ++k) inside &= s.orientation * dot(u, s.edgeCross[k]) >= 0;
            if (inside) return true;
        }
        for (int k = 0; k < 3; ++k)
            if (dot(u, s.corner[k]) >= cosReach) return true;
        for (int k = 0; k < 3; ++k) {
            if (!s.edgeIsArc[k]) continue;
            const Vec3d& n = s.edgeNormal[k];
            const double h = dot(u, n);
            const Vec3d inPlane = u - n * h;
            // The nearest point of the great circle is u's projection, at angle asin|h|, if it
            // falls on the arc (and on u's side of the sphere).
            if (std::abs(h) <= sinReach && dot(inPlane, s.corner[k] + s.corner[(k + 1) % 3]) > 0 &&
                dot(cross(s.corner[k], inPlane), n) >= 0 && dot(cross(inPlane, s.corner[(k + 1) % 3]), n) >= 0)
                return true;
        }
        return false;
    };
    Vec3d t, b;
    orthonormalBasis(axis, t, b);
    const double extraAngle = cosExtra > -1 ? std::acos(std::clamp(cosExtra, -1.0, 1.0)) : M_PI;
    auto theta = [&](double x) { return std::acos(std::clamp(1 - x * (1 - cosMax), -1.0, 1.0)); };
    // A cone that holds every direction of the cell [x0, x1] × [y0, y1]: about the direction at
    // (θm, φm), the middle of its θ and φ ranges; any direction (θ, φ) of the cell is within
    // sin θm·|φ − φm| (along the circle of latitude θm, no shorter than the great circle) plus
    // |θ − θm| (along the meridian) of it.
    auto mayOverlap = [&](double x0, double y0, double x1, double y1) {
        const double thetaA = theta(x0), thetaB = theta(x1), thetaM = 0.5 * (thetaA + thetaB);
        const double phiM = M_PI * (y0 + y1);
        const Vec3d cellAxis = coneDirection(axis, t, b, std::cos(thetaM), std::sin(thetaM), phiM);
        const double halfAngle = 0.5 * (thetaB - thetaA) + std::sin(thetaM) * M_PI * (y1 - y0) + kAngleSlack;
        const bool outsideExtra = cosExtra > -1 && angleBetween(cellAxis, extraAxis) > halfAngle + extraAngle;
        return [&seen, &within, cellAxis, halfAngle, outsideExtra](uint32_t i) {
            const Seen& s = seen[i];
            if (outsideExtra) return false;
            if (s.surroundsApex) return true;
            const double reach = halfAngle + s.angularRadius;
            if (reach >= M_PI) return true;
            // Beyond a right angle the arc test's "nearest point" reasoning needs |h| ≤ 1 only.
            return within(s, cellAxis, std::cos(reach), reach >= M_PI / 2 ? 1.0 : std::sin(reach));
        };
    };
    return ProjectionMap(depth, targets, mayOverlap);
}

ProjectionMap footprintMap(const Vec3d& centre, const Vec3d& direction, double halfSize, const std::vector<Target>& targets,
                           int depth) {
    Vec3d t, b;
    orthonormalBasis(direction, t, b);
    // Each target projected on the plane: a triangle (x[k], y[k]).
    struct Flat {
        double x[3], y[3];
        double orientation;  // sign of its signed area; 0: degenerate
    };
    std::vector<Flat> flat(targets.size());
    for (size_t i = 0; i < targets.size(); ++i) {
        Flat& f = flat[i];
        for (int k = 0; k < 3; ++k) {
            f.x[k] = dot(targets[i].corner[k] - centre, t);
            f.y[k] = dot(targets[i].corner[k] - centre, b);
        }
        const double area = (f.x[1] - f.x[0]) * (f.y[2] - f.y[0]) - (f.x[2] - f.x[0]) * (f.y[1] - f.y[0]);
        f.orientation = area > 0 ? 1.0 : area < 0 ? -1.0 : 0.0;
    }
    const double slack = 1e-6 * halfSize;
    auto mayOverlap = [&](double x0, double y0, double x1, double y1) {
        const double X0 = (2 * x0 - 1) * halfSize, X1 = (2 * x1 - 1) * halfSize;
        const double Y0 = (2 * y0 - 1) * halfSize, Y1 = (2 * y1 - 1) * halfSize;
        return [&flat, &targets, slack, X0, X1, Y0, Y1](uint32_t i) {
            const Flat& f = flat[i];
            const double reach = targets[i].radius + slack;
            for (int k = 0; k < 3; ++k)
                if (segmentToRectangle(f.x[k], f.y[k], f.x[(k + 1) % 3], f.y[(k + 1) % 3], X0, Y0, X1, Y1) <= reach) return true;
            // No edge near the rectangle: it meets the triangle only if it lies inside it.
            if (f.orientation == 0) return false;
            const double cx = 0.5 * (X0 + X1), cy = 0.5 * (Y0 + Y1);
            for (int k = 0; k < 3; ++k) {
                const int j = (k + 1) % 3;
                if (f.orientation * ((f.x[j] - f.x[k]) * (cy - f.y[k]) - (f.y[j] - f.y[k]) * (cx - f.x[k])) < 0) return false;
            }
            return true;
        };
    };
    return ProjectionMap(depth, targets, mayOverlap);
}

}  // namespace qsgi
