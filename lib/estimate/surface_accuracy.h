// Accuracy where the eye looks (issue 47): a frame's vertex irradiance interpolated linearly across
// each triangle — what a viewer, Blender or an engine shows — against a path tracer's irradiance at
// points spread uniformly by area (scripts/reference.py --surface N), overall and by band: where
// two surfaces touch or nearly do (a block's foot, the ceiling round a panel), along the edges of a
// surface, and the interior. The reference's own noise (each point's standard error) is reported
// and taken out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "scene/scene.h"
#include "util/vecmath.h"

namespace qsgi {

// One point of a surface reference: on `triangle` (a face index of the mesh it was drawn on) at
// weights (1 − b1 − b2, b1, b2) of its corners; its world position and the normal of the side
// that receives light; E and its standard error; hidden (no light reaches it and it lies inside
// or under closed geometry: left out of scores).
struct SurfacePoint {
    uint32_t triangle = 0;
    float b1 = 0, b2 = 0;
    Vec3f position{0.0f}, normal{0.0f};
    Vec3f irradiance{0.0f}, standardError{0.0f};
    bool hidden = false;
};

// Where a point lies on a frame's mesh: a triangle and the barycentrics of the point's projection
// onto it. Found by position, not by the triangle index the point was drawn with, so that a frame
// of the same surface tessellated otherwise — refined by --subdivide — is scored at the same
// places: the triangle within 10⁻⁴ of the mesh's extent of the point (float storage moves points
// far less) whose front faces the point's normal most, then the nearest, then the first. On a
// conforming mesh the interpolation is continuous across shared edges, so which of two coplanar
// triangles takes a point on their edge changes nothing; at a crease or where two surfaces touch,
// the normal picks the point's own side.
struct PointOnMesh {
    uint32_t triangle = 0;
    double b1 = 0, b2 = 0;
};
// Throws std::invalid_argument, saying which point, when one lies on no triangle of the mesh
// (another scene, another pose).
std::vector<PointOnMesh> locateOnMesh(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      const std::vector<Triangle>& triangles, const std::vector<SurfacePoint>& points);

// The vertex values interpolated at a located point.
Vec3f interpolatedAt(const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values, const PointOnMesh& at);

// The bands partition the points that are not hidden (each at its place on the mesh), in this order
// of precedence:
// Contact: within `width` of a triangle of another piece of surface (edgeConnectedPieces: a piece
//   is joined across shared edges, so a block on a floor is another piece, a box's walls one).
// Edge: within `width` of an edge of a surface (MeshEdges: border, non-manifold, crease > 45°).
// Interior: the rest.
enum class SurfaceBand : uint8_t { Contact, Edge, Interior };
std::vector<SurfaceBand> surfaceBands(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                      const std::vector<Triangle>& triangles, const std::vector<PointOnMesh>& located,
                                      float width);

// NaN figures where no point counts (an empty band): no figure, not a perfect one. A reference whose
// mean is 0 (a black scene) gives absolute figures, as ErrorStats does.
struct SurfaceErrorStats {
    size_t points = 0;
    double relativeRms = 0;     // sqrt(mean |E_interp − E_ref|²) / mean |E_ref|, over points and RGB
    double relativeBias = 0;    // mean (E_interp − E_ref) / mean |E_ref|
    double referenceNoise = 0;  // sqrt(mean stderr²) / mean |E_ref|: what the reference's noise adds
    double withoutNoise = 0;    // sqrt(max(0, mean |E_interp − E_ref|² − mean stderr²)) / mean |E_ref|
};

struct SurfaceAccuracyReport {
    size_t hidden = 0;
    SurfaceErrorStats all, contact, edge, interior;
};

// Locates the points (locateOnMesh, which may throw) and scores `values` there.
SurfaceAccuracyReport compareOverSurface(const std::vector<Vec3f>& positions, const std::vector<Vec3f>& normals,
                                         const std::vector<Triangle>& triangles, const std::vector<Vec3f>& values,
                                         const std::vector<SurfacePoint>& points, float width);

}  // namespace qsgi
