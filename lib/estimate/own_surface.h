// The own surface of a vertex (docs/design.md §5): the triangles reached from v across shared (welded)
// vertices whose front face normals lie strictly within 45° of n_v, clipped to the cylinder C_v
// of radius r around v's normal, |height| ≤ r. Its largest heights above and below v's tangent
// plane bound where photons that belong to v's surface can land: DETP counts a segment only if
// its impact lies at most ε_v⁺ in front of the plane, the photon map only impacts within
// [−ε_v⁻, ε_v⁺]. Other objects never enter it, so a light panel under a ceiling does not widen
// the ceiling's band.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "scene/mesh_topology.h"
#include "scene/scene.h"

namespace qsgi {

class OwnSurfaceTree;

struct OwnSurface {
    // No incident triangle within 45° of n_v (a crease vertex with an averaged normal): the
    // estimators fall back to the `paper` rule there.
    bool empty = true;
    // ε_v⁺: the largest height of the clipped surface above the tangent plane, rounded to the
    // nearest whole number of scene epsilons (halves down), at most r, plus the scene epsilon.
    // Rounded so that the rounding noise of a flat or convex surface (a tilted plane's corners
    // lie 1e-8 above or below it) never decides it, and so that OwnSurfaceTree can prove it from
    // v's incident triangles alone almost everywhere (docs/design.md §5).
    // ε_v⁻: the largest depth below the plane (≤ r), plus the scene epsilon; only where asked
    // for (the photon map's band), else 0.
    float epsAbove = 0, epsBelow = 0;
    // u_v: unit tangent direction from v toward the area centroid of its incident own-surface
    // triangles; zero where that centroid is v itself (an interior vertex of a symmetric fan).
    Vec3f towardSurface{0.0f};
    // ε_v⁺ was proved by OwnSurfaceQuery::tree without walking the own surface (for the counts).
    bool provedByTree = false;
    // Triangles of the own surface the walk visited (0 when the tree proved it): its cost.
    uint32_t trianglesWalked = 0;
};

// Cosine of the 45° limit between a face normal and n_v (strict: dot > this).
constexpr float kOwnSurfaceCos = 0.70710678f;

// Reusable working memory of findOwnSurface (one per thread).
struct OwnSurfaceScratch {
    std::vector<uint32_t> visitedStamp;   // per triangle: the search that last visited it
    std::vector<uint32_t> vertexStamp;    // per vertex: the search that placed it in `local`
    std::vector<uint32_t> expandedStamp;  // per welded vertex: the search that expanded from it
    std::vector<std::array<double, 3>> local;  // per vertex: its place in v's frame (x, y, height)
    uint32_t stamp = 0;
    std::vector<uint32_t> frontier;
};

// What a caller needs of the own surface, and what may shorten the search.
struct OwnSurfaceQuery {
    bool depthBelow = true;  // compute ε_v⁻ (a walk over the whole own surface)
    // Without ε_v⁻: first ask this tree (built for the same pose) whether anything near v could
    // rise higher than v's incident triangles; the answer is the same as without it.
    const OwnSurfaceTree* tree = nullptr;
};

// Own surface of vertex v in the scene's current pose. frontNormals: Scene::frontFaceNormals().
OwnSurface findOwnSurface(uint32_t v, const Scene& scene, const MeshTopology& topology,
                          const std::vector<Vec3f>& frontNormals, float radius, OwnSurfaceScratch& scratch,
                          const OwnSurfaceQuery& query = {});

}  // namespace qsgi
