// Whether the mesh is fine enough to carry the lighting (issue 35). Radiosity exists only at
// vertices and is interpolated across each triangle, and every estimator gathers within a radius r
// of a vertex: a triangle whose edge is several radii long shows no shadow, no patch of light and no
// gradient smaller than itself, whatever the photon count (a box on a floor of two triangles casts
// no shadow at all). qsgi warns when triangles with an edge past kCoarseEdgeRadii · r cover at least
// kCoarseAreaWarning of the surface, saying how much and with how many vertices (RenderJob, which
// inspect and render share); inspect reports them always.
#pragma once

#include <cstddef>

#include "scene/scene.h"

namespace qsgi {

// An edge longer than this many radii makes a triangle coarse: beyond 4 r a triangle spans more
// than two vertices' gathering discs side by side, so lighting that varies over a disc's width
// (a contact shadow, a spot's edge) falls between its vertices.
constexpr double kCoarseEdgeRadii = 4.0;

// The share of the surface coarse triangles must cover for a warning: a few long triangles on a
// thin part (data/walker's legs: 32 triangles, 0.4 % of its area) are reported by inspect, not
// warned about on every run.
constexpr double kCoarseAreaWarning = 0.01;

struct MeshResolution {
    double edgeLimit = 0;         // kCoarseEdgeRadii · r
    size_t coarseTriangles = 0;   // with an edge longer than edgeLimit
    size_t coarseVertices = 0;    // the distinct vertices of those triangles
    double coarseArea = 0;        // their area
    double totalArea = 0;         // of every triangle
    double longestEdge = 0;

    double coarseAreaShare() const { return totalArea > 0 ? coarseArea / totalArea : 0.0; }
};

// The scene's current pose (the rest pose, at load) measured against radius r.
MeshResolution meshResolution(const Scene& scene, float radius);

}  // namespace qsgi
