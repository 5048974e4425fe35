#include "estimate/own_surface.h"

#include "estimate/own_surface_tree.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace qsgi {

namespace {

// A point of a triangle in v's frame: (x, y) on the tangent plane, h along n_v.
struct Local {
    double x, y, h;
};

Local lerp(const Local& a, const Local& b, double s) {
    return {a.x + (b.x - a.x) * s, a.y + (b.y - a.y) * s, a.h + (b.h - a.h) * s};
}

// A triangle clipped by two planes has at most five corners.
struct Polygon {
    Local p[5];
    int size = 0;
    void push(const Local& l) { p[size++] = l; }
};

// Clips a convex polygon to h ≤ limit (sign = +1) or h ≥ −limit (sign = −1): Sutherland–Hodgman.
Polygon clipHeight(const Polygon& poly, double limit, double sign) {
    Polygon out;
    for (int i = 0; i < poly.size; ++i) {
        const Local& a = poly.p[i];
        const Local& b = poly.p[(i + 1) % poly.size];
        const double da = limit - sign * a.h, db = limit - sign * b.h;  // ≥ 0: inside
        if (da >= 0) out.push(a);
        if ((da >= 0) != (db >= 0)) out.push(lerp(a, b, da / (da - db)));
    }
    return out;
}

bool insideConvex(const Polygon& poly, double x, double y) {
    double sign = 0;
    for (int i = 0; i < poly.size; ++i) {
        const Local& a = poly.p[i];
        const Local& b = poly.p[(i + 1) % poly.size];
        const double c = (b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x);
        if (c == 0) continue;
        if (sign == 0) sign = c;
        else if ((c > 0) != (sign > 0)) return false;
    }
    return true;
}

// Height range of a triangle clipped to the cylinder {x² + y² ≤ r², |h| ≤ r}. Returns false if
// the clipped triangle is empty. The height is affine over the triangle, so its extremes over the
// convex region lie at polygon corners inside the disc, where edges cross the circle, or where
// the circle touches the height's gradient direction.
bool clippedHeightRange(const Local tri[3], double r, double& lo, double& hi) {
    const double cornerLo = std::min({tri[0].h, tri[1].h, tri[2].h}), cornerHi = std::max({tri[0].h, tri[1].h, tri[2].h});
    // Cheap rejection first: all corners on one side of the cylinder's bounding box.
    for (int axis = 0; axis < 3; ++axis) {
        auto coord = [&](const Local& l) { return axis == 0 ? l.x : axis == 1 ? l.y : l.h; };
        if (std::min({coord(tri[0]), coord(tri[1]), coord(tri[2])}) > r) return false;
        if (std::max({coord(tri[0]), coord(tri[1]), coord(tri[2])}) < -r) return false;
    }
    // A triangle well inside the cylinder is its own clip: its extremes are at its corners, and
    // nothing below adds another (its edges meet no circle in [0, 1], the gradient's points on
    // the circle lie outside it) — the same range the general case finds, corner for corner.
    const double inner2 = r * r * (1 - 1e-9);
    bool inside = true;
    for (int i = 0; i < 3; ++i)
        inside = inside && tri[i].x * tri[i].x + tri[i].y * tri[i].y <= inner2 && std::fabs(tri[i].h) < r;
    if (inside) {
        lo = cornerLo;
        hi = cornerHi;
        return true;
    }
    Polygon poly;
    for (int i = 0; i < 3; ++i) poly.push(tri[i]);
    poly = clipHeight(poly, r, +1);
    if (poly.size >= 3) poly = clipHeight(poly, r, -1);
    if (poly.size < 3) return false;
    lo = std::numeric_limits<double>::max();
    hi = -std::numeric_limits<double>::max();
    auto consider = [&](double h) {
        lo = std::min(lo, h);
        hi = std::max(hi, h);
    };
    const double r2 = r * r;
    for (int i = 0; i < poly.size; ++i) {
        const Local& a = poly.p[i];
        const Local& b = poly.p[(i + 1) % poly.size];
        if (a.x * a.x + a.y * a.y <= r2) consider(a.h);
        // |a + s(b − a)|² = r² for s in [0, 1].
        const double dx = b.x - a.x, dy = b.y - a.y;
        const double qa = dx * dx + dy * dy, qb = 2 * (a.x * dx + a.y * dy), qc = a.x * a.x + a.y * a.y - r2;
        const double disc = qb * qb - 4 * qa * qc;
        if (qa > 0 && disc >= 0) {
            const double root = std::sqrt(disc);
            for (double s : {(-qb - root) / (2 * qa), (-qb + root) / (2 * qa)})
                if (s >= 0 && s <= 1) consider(a.h + (b.h - a.h) * s);
        }
    }
    // Height gradient over the plane from three non-collinear corners of the original triangle.
    const double ux = tri[1].x - tri[0].x, uy = tri[1].y - tri[0].y, uh = tri[1].h - tri[0].h;
    const double vx = tri[2].x - tri[0].x, vy = tri[2].y - tri[0].y, vh = tri[2].h - tri[0].h;
    const double det = ux * vy - uy * vx;
    if (det != 0) {
        const double gx = (uh * vy - vh * uy) / det, gy = (vh * ux - uh * vx) / det;
        const double g = std::hypot(gx, gy);
        if (g > 0)
            for (double sign : {1.0, -1.0}) {
                const double x = sign * r * gx / g, y = sign * r * gy / g;
                const double h = tri[0].h + gx * (x - tri[0].x) + gy * (y - tri[0].y);
                if (std::fabs(h) <= r && insideConvex(poly, x, y)) consider(h);
            }
    }
    // The height is affine over the triangle, so the clipped part's lies within the corners';
    // rounding (a sliver's gradient) may not take it out: OwnSurfaceTree bounds corners only.
    // Whether the clip is empty is decided before, as it always was.
    if (!(lo <= hi)) return false;
    lo = std::max(lo, cornerLo);
    hi = std::min(hi, cornerHi);
    if (lo > hi) lo = cornerLo, hi = cornerHi;  // rounding beyond repair: the corners' range
    return true;
}

}  // namespace

OwnSurface findOwnSurface(uint32_t v, const Scene& scene, const MeshTopology& topology,
                          const std::vector<Vec3f>& frontNormals, float radius, OwnSurfaceScratch& scratch,
                          const OwnSurfaceQuery& query) {
    OwnSurface own;
    const Vec3d origin(scene.positions[v]), n(scene.normals[v]);
    Vec3d t, b;
    orthonormalBasis(n, t, b);
    const double r = radius;
    // Each search stamps the triangles it visits and the vertices it has placed in v's frame or
    // expanded from; a new stamp forgets the last search.
    if (scratch.visitedStamp.size() != scene.triangleCount() || scratch.vertexStamp.size() != scene.vertexCount() ||
        scratch.stamp == UINT32_MAX) {
        scratch.visitedStamp.assign(scene.triangleCount(), 0);
        scratch.vertexStamp.assign(scene.vertexCount(), 0);
        scratch.expandedStamp.assign(scene.vertexCount(), 0);
        scratch.local.resize(scene.vertexCount());
        scratch.stamp = 0;
    }
    const uint32_t stamp = ++scratch.stamp;
    auto local = [&](uint32_t vertex) {
        if (scratch.vertexStamp[vertex] != stamp) {
            const Vec3d d = Vec3d(scene.positions[vertex]) - origin;
            scratch.local[vertex] = {dot(d, t), dot(d, b), dot(d, n)};
            scratch.vertexStamp[vertex] = stamp;
        }
        const auto& l = scratch.local[vertex];
        return Local{l[0], l[1], l[2]};
    };
    auto qualifies = [&](uint32_t tri, double& lo, double& hi) {
        if (!(dot(frontNormals[tri], scene.normals[v]) > kOwnSurfaceCos)) return false;
        const Triangle& T = scene.triangles[tri];
        const Local corners[3] = {local(T.v[0]), local(T.v[1]), local(T.v[2])};
        return clippedHeightRange(corners, r, lo, hi);
    };

    // Breadth-first over triangles sharing welded vertices, from the triangles at v.
    double lowest = 0, highest = 0;
    Vec3d centroidSum(0.0);
    double areaSum = 0;
    auto firstVisit = [&](uint32_t tri) {
        if (scratch.visitedStamp[tri] == stamp) return false;
        scratch.visitedStamp[tri] = stamp;
        return true;
    };
    std::vector<uint32_t>& frontier = scratch.frontier;
    frontier.clear();
    for (const uint32_t* it = topology.trianglesBegin(v); it != topology.trianglesEnd(v); ++it) {
        double lo, hi;
        firstVisit(*it);
        if (!qualifies(*it, lo, hi)) continue;
        frontier.push_back(*it);
        lowest = std::min(lowest, lo);
        highest = std::max(highest, hi);
        const Triangle& T = scene.triangles[*it];
        const double area = scene.triangleArea(*it);
        centroidSum += (Vec3d(scene.positions[T.v[0]]) + Vec3d(scene.positions[T.v[1]]) + Vec3d(scene.positions[T.v[2]])) *
                       (area / 3.0);
        areaSum += area;
    }
    own.empty = frontier.empty();
    const double eps = scene.sceneEpsilon();
    if (own.empty) return own;
    // ε⁺ counts whole scene epsilons: a height below half of one is 0 (see OwnSurface).
    auto level = [&](double height) { return std::floor(height / eps + 0.5); };
    auto finish = [&] {
        own.epsAbove = float(std::min(level(highest) * eps, r) + eps);
        own.epsBelow = query.depthBelow ? float(std::min(-lowest, r) + eps) : 0.0f;
        if (areaSum > 0) {
            const Vec3d toCentroid = centroidSum / areaSum - origin;
            const Vec3d tangential = toCentroid - n * dot(toCentroid, n);
            // Below ~1e-9 of the radius the direction is rounding noise: no preferred side.
            if (length(tangential) > 1e-9 * r) own.towardSurface = Vec3f(normalize(tangential));
        }
        return own;
    };
    // The shortcut: if no triangle near v that could belong to its own surface (of v's piece,
    // facing within 45°, within the cylinder's ball of radius r√2) rises to the next level, the walk below
    // could only find what the incident triangles gave. The tree bounds corners; a triangle it
    // cannot rule out is judged exactly as the walk judges it. Where the incident triangles
    // already rise a whole epsilon, v sits in a hollow whose wall the tree would find only to
    // send v to the walk: it goes there at once. The answer is the walk's either way.
    if (query.tree && !query.depthBelow && level(highest) == 0) {
        // The walk's cylinder, in v's frame, lies within r√2 of v — but the frame is built on a
        // float normal, a few 1e-8 off unit length: the ball is widened far past that.
        const double reach = r * std::sqrt(2.0) * (1 + 1e-5);
        const bool rises = query.tree->anyRising(query.tree->pieceOfVertex(v), origin, n, double(kOwnSurfaceCos), reach, 0.5 * eps,
                                                 [&](uint32_t tri) {
                                                     if (scratch.visitedStamp[tri] == stamp) return false;
                                                     double lo, hi;
                                                     return qualifies(tri, lo, hi) && level(hi) > 0;
                                                 });
        own.provedByTree = !rises;
        if (!rises) return finish();
    }
    // A corner's triangles are looked at once, whichever reached triangle shares it.
    for (size_t i = 0; i < frontier.size(); ++i) {
        const Triangle& T = scene.triangles[frontier[i]];
        for (uint32_t corner : T.v) {
            const uint32_t welded = topology.weldedId(corner);
            if (scratch.expandedStamp[welded] == stamp) continue;
            scratch.expandedStamp[welded] = stamp;
            for (const uint32_t* it = topology.trianglesBegin(corner); it != topology.trianglesEnd(corner); ++it) {
                if (!firstVisit(*it)) continue;
                double lo, hi;
                if (!qualifies(*it, lo, hi)) continue;
                frontier.push_back(*it);
                lowest = std::min(lowest, lo);
                highest = std::max(highest, hi);
            }
        }
    }
    own.trianglesWalked = uint32_t(frontier.size());
    return finish();
}

}  // namespace qsgi
