#include "estimate/surface_accuracy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "estimate/accuracy.h"
#include "estimate/mesh_bands.h"
#include "scene/triangle_grid.h"
#include "scene/mesh_topology.h"

namespace qsgi {

namespace {
// A per-vertex quantity (positions, values) at weights (1 − b1 − b2, b1, b2) of the triangle's corners.
Vec3d mixedAt(const std::vector<Vec3f>& perVertex, const Triangle& t, double b1, double b2) {
    return Vec3d(perVertex[t.v[0]]) * (1 - b1 - b2) + Vec3d(perVertex[t.v[1]]) * b1 + Vec3d(perVertex[t.v[2]]) * b2;
}

// Barycentrics (of corners 1 and 2) of p's projection onto the triangle's plane, clamped into it.
std::pair<double, double> barycentricsOf(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d00 = dot(ab, ab), d01 = dot(ab, ac), d11 = dot(ac, ac), d20 = dot(ap, ab), d21 = dot(ap, ac);
    const double det = d00 * d11 - d01 * d01;
    if (!(det > 0)) return {0.0, 0.0};  // a degenerate triangle: its first corner
    double b1 = std::max(0.0, (d11 * d20 - d01 * d21) / det), b2 = std::max(0.0, (d00 * d21 - d01 * d20) / det);
    if (b1 + b2 > 1) {
        const double sum = b1 + b2;
        b1 /= sum, b2 /= sum;
    }
    return {b1, b2};
}

SurfaceErrorStats statsOf(const std::vector<Vec3f>& interpolated, const std::vector<SurfacePoint>& points,
                          const std::vector<uint8_t>& counted) {
    RelativeErrorSums sums;
    double noise = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        if (!counted[i]) continue;
        sums.add(interpolated[i], points[i].irradiance);
        for (int c = 0; c < 3; ++c) noise += double(points[i].standardError[c]) * double(points[i].standardError[c]);
    }
    SurfaceErrorStats s;
    s.points = sums.count;
    if (s.points == 0) {  // nothing to score: no figure, not a perfect one
        s.relativeRms = s.relativeBias = s.referenceNoise = s.withoutNoise = std::numeric_limits<double>::quiet_NaN();
        return s;
    }
    s.relativeRms = sums.relativeRms();
    s.relativeBias = sums.relativeBias();
    s.referenceNoise = std::sqrt(noise / sums.channels()) / sums.scale();
    s.withoutNoise = std::sqrt(std::max(0.0, (sums.squared - noise) / sums.channels())) / sums.scale();
    return s;
}
}  // namespace

std::vector<PointOnMesh> locateOnMesh(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      const std::vector<Triangle>& triangles, const std::vector<SurfacePoint>& points) {
    Bounds3f bounds;
    for (const Vec3f& p : positions) bounds.extend(p);
    const double tolerance = 1e-4 * double(maxComponent(bounds.diagonal()));
    const TriangleGrid grid(positions, triangles, float(tolerance));
    std::vector<PointOnMesh> located(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        const Vec3d p(points[i].position);
        const Vec3f n = points[i].normal;
        int64_t best = -1;
        double bestFacing = 0, bestDistance = 0;
        grid.anyNear(p, [&](uint32_t t) {
            const Triangle& T = triangles[t];
            const double d2 = squaredDistanceToTriangle(p, Vec3d(positions[T.v[0]]), Vec3d(positions[T.v[1]]), Vec3d(positions[T.v[2]]));
            if (!(d2 <= tolerance * tolerance)) return false;
            const double facing = double(dot(frontFaceNormal(positions, normals, T), n));
            if (best < 0 || facing > bestFacing + 1e-6 || (facing >= bestFacing - 1e-6 && d2 < bestDistance)) {
                best = t;
                bestFacing = facing;
                bestDistance = d2;
            }
            return false;
        });
        if (best < 0)
            throw std::invalid_argument("point " + std::to_string(i) + " lies on no triangle of the frame (none within " +
                                        std::to_string(tolerance) + "): drawn on another scene or pose");
        const Triangle& T = triangles[size_t(best)];
        const auto [b1, b2] = barycentricsOf(p, Vec3d(positions[T.v[0]]), Vec3d(positions[T.v[1]]), Vec3d(positions[T.v[2]]));
        located[i] = {uint32_t(best), b1, b2};
    }
    return located;
}

Vec3f interpolatedAt(const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values, const PointOnMesh& at) {
    return Vec3f(mixedAt(values, triangles[at.triangle], at.b1, at.b2));
}

std::vector<SurfaceBand> surfaceBands(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      const std::vector<Triangle>& triangles, const std::vector<PointOnMesh>& located,
                                      float width) {
    const MeshTopology topology(positions, triangles);
    const std::vector<uint32_t> piece = topology.edgeConnectedPieces(triangles);
    const MeshEdges edges(positions, normals, triangles, topology, width);
    const TriangleGrid grid(positions, triangles, width);
    const double width2 = double(width) * double(width);
    std::vector<SurfaceBand> band(located.size(), SurfaceBand::Interior);
    for (size_t i = 0; i < located.size(); ++i) {
        const uint32_t own = piece.at(located[i].triangle);
        const Vec3d p = mixedAt(positions, triangles[located[i].triangle], located[i].b1, located[i].b2);
        const bool contact = grid.anyNear(p, [&](uint32_t t) {
            const Triangle& T = triangles[t];
            return piece[t] != own &&
                   squaredDistanceToTriangle(p, Vec3d(positions[T.v[0]]), Vec3d(positions[T.v[1]]), Vec3d(positions[T.v[2]])) <= width2;
        });
        if (contact) band[i] = SurfaceBand::Contact;
        else if (edges.within(Vec3f(p))) band[i] = SurfaceBand::Edge;
    }
    return band;
}

SurfaceAccuracyReport compareOverSurface(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                         const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                         const std::vector<SurfacePoint>& points, float width) {
    const std::vector<PointOnMesh> located = locateOnMesh(positions, normals, triangles, points);
    std::vector<Vec3f> interpolated(points.size());
    for (size_t i = 0; i < points.size(); ++i) interpolated[i] = interpolatedAt(triangles, values, located[i]);
    const std::vector<SurfaceBand> band = surfaceBands(positions, normals, triangles, located, width);
    SurfaceAccuracyReport r;
    auto counted = [&](auto&& in) {
        std::vector<uint8_t> keep(points.size());
        for (size_t i = 0; i < points.size(); ++i) keep[i] = !points[i].hidden && in(i);
        return keep;
    };
    for (const SurfacePoint& p : points) r.hidden += p.hidden;
    r.all = statsOf(interpolated, points, counted([](size_t) { return true; }));
    r.contact = statsOf(interpolated, points, counted([&](size_t i) { return band[i] == SurfaceBand::Contact; }));
    r.edge = statsOf(interpolated, points, counted([&](size_t i) { return band[i] == SurfaceBand::Edge; }));
    r.interior = statsOf(interpolated, points, counted([&](size_t i) { return band[i] == SurfaceBand::Interior; }));
    return r;
}

}  // namespace qsgi
