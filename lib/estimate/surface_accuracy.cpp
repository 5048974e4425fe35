#include "estimate/surface_accuracy.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "estimate/mesh_bands.h"
#include "scene/mesh_topology.h"

namespace qsgi {

namespace {
Vec3d pointOn(const std::vector<Vec3f>& positions, const Triangle& t, const SurfacePoint& p) {
    const double b1 = p.b1, b2 = p.b2, b0 = 1 - b1 - b2;
    return Vec3d(positions[t.v[0]]) * b0 + Vec3d(positions[t.v[1]]) * b1 + Vec3d(positions[t.v[2]]) * b2;
}

SurfaceErrorStats statsOf(const std::vector<Vec3f>& interpolated, const std::vector<SurfacePoint>& points,
                          const std::vector<uint8_t>& counted) {
    SurfaceErrorStats s;
    double squared = 0, difference = 0, reference = 0, noise = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        if (!counted[i]) continue;
        for (int c = 0; c < 3; ++c) {
            const double d = double(interpolated[i][c]) - double(points[i].irradiance[c]);
            squared += d * d;
            difference += d;
            reference += std::fabs(double(points[i].irradiance[c]));
            noise += double(points[i].standardError[c]) * double(points[i].standardError[c]);
        }
        ++s.points;
    }
    if (s.points == 0) return s;
    const double n = 3.0 * double(s.points);
    const double scale = reference / n > 0 ? reference / n : 1.0;
    s.relativeRms = std::sqrt(squared / n) / scale;
    s.relativeBias = difference / n / scale;
    s.referenceNoise = std::sqrt(noise / n) / scale;
    s.withoutNoise = std::sqrt(std::max(0.0, (squared - noise) / n)) / scale;
    return s;
}
}  // namespace

Vec3f interpolatedAt(const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values, const SurfacePoint& point) {
    if (point.triangle >= triangles.size())
        throw std::invalid_argument("a point names triangle " + std::to_string(point.triangle) + " of a mesh of " +
                                    std::to_string(triangles.size()));
    const Triangle& t = triangles[point.triangle];
    const double b1 = point.b1, b2 = point.b2, b0 = 1 - b1 - b2;
    return Vec3f(Vec3d(values[t.v[0]]) * b0 + Vec3d(values[t.v[1]]) * b1 + Vec3d(values[t.v[2]]) * b2);
}

void checkDrawnOn(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles, const std::vector<SurfacePoint>& points) {
    Bounds3f bounds;
    for (const Vec3f& p : positions) bounds.extend(p);
    const double tolerance = 1e-4 * double(maxComponent(bounds.diagonal()));
    for (size_t i = 0; i < points.size(); ++i) {
        const std::string which = "point " + std::to_string(i);
        if (points[i].triangle >= triangles.size())
            throw std::invalid_argument(which + " names triangle " + std::to_string(points[i].triangle) + " but the frame has " +
                                        std::to_string(triangles.size()) + ": another mesh");
        const Vec3d off = pointOn(positions, triangles[points[i].triangle], points[i]) - Vec3d(points[i].position);
        if (!(length(off) <= tolerance))
            throw std::invalid_argument(which + " lies " + std::to_string(length(off)) +
                                        " from the place its triangle and barycentrics name in the frame: another mesh or pose");
    }
}

std::vector<SurfaceBand> surfaceBands(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      const std::vector<Triangle>& triangles, const std::vector<SurfacePoint>& points,
                                      float width) {
    const MeshTopology topology(positions, triangles);
    const std::vector<uint32_t> piece = edgeConnectedPieces(triangles, topology);
    const MeshEdges edges(positions, normals, triangles, topology, width);
    const TriangleGrid grid(positions, triangles, width);
    const double width2 = double(width) * double(width);
    std::vector<SurfaceBand> band(points.size(), SurfaceBand::Interior);
    for (size_t i = 0; i < points.size(); ++i) {
        const uint32_t own = piece.at(points[i].triangle);
        const Vec3d p = pointOn(positions, triangles[points[i].triangle], points[i]);
        bool contact = false;
        for (uint32_t t : grid.near(p)) {
            if (piece[t] == own) continue;
            const Triangle& T = triangles[t];
            if ((contact = squaredDistanceToTriangle(p, Vec3d(positions[T.v[0]]), Vec3d(positions[T.v[1]]), Vec3d(positions[T.v[2]])) <=
                           width2))
                break;
        }
        if (contact) band[i] = SurfaceBand::Contact;
        else if (edges.within(Vec3f(p))) band[i] = SurfaceBand::Edge;
    }
    return band;
}

SurfaceAccuracyReport compareOverSurface(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                         const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                         const std::vector<SurfacePoint>& points, float width) {
    std::vector<Vec3f> interpolated(points.size());
    for (size_t i = 0; i < points.size(); ++i) interpolated[i] = interpolatedAt(triangles, values, points[i]);
    const std::vector<SurfaceBand> band = surfaceBands(positions, normals, triangles, points, width);
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
