#include "estimate/accuracy.h"

#include <algorithm>
#include <cmath>

#include "estimate/mesh_bands.h"
#include "scene/triangle_grid.h"
#include "estimate/point_index.h"
#include "scene/mesh_topology.h"

namespace qsgi {

std::vector<bool> verticesNearCreases(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      float distance) {
    std::vector<bool> near(positions.size(), false);
    if (!(distance > 0)) return near;
    const PointIndex index(positions);
    const float cosCrease = std::cos(30.0f * 3.14159265f / 180.0f);
    std::vector<size_t> found;
    std::vector<float> d2;
    for (size_t v = 0; v < positions.size(); ++v) {
        index.withinRadius(positions[v], distance * distance, found, d2);
        for (size_t w : found)
            if (dot(normals[v], normals[w]) < cosCrease) {
                near[v] = true;
                break;
            }
    }
    return near;
}

ErrorStats errorStats(const std::vector<Vec3f>& values, const std::vector<Vec3f>& reference, const std::vector<bool>& subset) {
    RelativeErrorSums sums;
    for (size_t v = 0; v < values.size() && v < reference.size(); ++v)
        if (subset.empty() || subset[v]) sums.add(values[v], reference[v]);
    ErrorStats s;
    s.vertices = sums.count;
    if (s.vertices == 0) return s;
    s.relativeRms = sums.relativeRms();
    s.relativeBias = sums.relativeBias();
    return s;
}

std::vector<EdgeRegion> edgeRegions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                    const std::vector<Triangle>& triangles, float radius) {
    const MeshTopology topology(positions, triangles);
    const MeshEdges edges(positions, normals, triangles, topology, radius);
    std::vector<EdgeRegion> region(positions.size(), EdgeRegion::Interior);
    for (size_t v = 0; v < positions.size(); ++v) {
        if (edges.vertexOnEdge(uint32_t(v))) region[v] = EdgeRegion::OnEdge;
        else if (edges.within(positions[v])) region[v] = EdgeRegion::NearEdge;
    }
    return region;
}

std::vector<bool> touchingOtherSurfaces(const std::vector<Vec3f>& positions, const std::vector<Triangle>& triangles,
                                        float tolerance) {
    std::vector<bool> touching(positions.size(), false);
    if (positions.empty() || triangles.empty()) return touching;
    const MeshTopology topology(positions, triangles);
    const TriangleGrid grid(positions, triangles, tolerance);
    const double tolerance2 = double(tolerance) * double(tolerance);
    for (uint32_t v = 0; v < positions.size(); ++v) {
        const Vec3d p(positions[v]);
        touching[v] = grid.anyNear(p, [&](uint32_t t) {
            // Its own triangles (at its welded position) do not count.
            if (std::binary_search(topology.trianglesBegin(v), topology.trianglesEnd(v), t)) return false;
            const Triangle& tri = triangles[t];
            return squaredDistanceToTriangle(p, Vec3d(positions[tri.v[0]]), Vec3d(positions[tri.v[1]]), Vec3d(positions[tri.v[2]])) <=
                   tolerance2;
        });
    }
    return touching;
}

AccuracyReport compareSolutions(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                const std::vector<Vec3f>& reference, float radius, const std::vector<bool>& only) {
    AccuracyReport r;
    auto within = [&](std::vector<bool> in) {
        if (only.empty()) return in;
        for (size_t v = 0; v < in.size(); ++v) in[v] = in[v] && v < only.size() && only[v];
        return in;
    };
    r.all = errorStats(values, reference, only);
    const std::vector<EdgeRegion> region = edgeRegions(positions, normals, triangles, radius);
    auto subset = [&](EdgeRegion which) {
        std::vector<bool> in(region.size());
        for (size_t v = 0; v < region.size(); ++v) in[v] = region[v] == which;
        return within(std::move(in));
    };
    r.edge = errorStats(values, reference, subset(EdgeRegion::OnEdge));
    r.nearEdge = errorStats(values, reference, subset(EdgeRegion::NearEdge));
    r.interior = errorStats(values, reference, subset(EdgeRegion::Interior));
    // Touching: within 10^-5 of the scene's size of another surface (the scenes' contacts are
    // exact; a tolerance keeps float rounding of placed meshes from hiding them).
    Bounds3f bounds;
    for (const Vec3f& p : positions) bounds.extend(p);
    r.contact = errorStats(values, reference, within(touchingOtherSurfaces(positions, triangles, 1e-5f * bounds.extent())));
    return r;
}

}  // namespace qsgi
