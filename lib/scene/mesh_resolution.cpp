#include "scene/mesh_resolution.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace qsgi {

MeshResolution meshResolution(const Scene& scene, float radius) {
    MeshResolution m;
    m.edgeLimit = kCoarseEdgeRadii * double(radius);
    std::vector<uint8_t> counted(scene.vertexCount(), 0);
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) {
        const Triangle& tri = scene.triangles[t];
        double longest = 0;
        for (int e = 0; e < 3; ++e)
            longest = std::max(longest, length(Vec3d(scene.positions[tri.v[(e + 1) % 3]]) - Vec3d(scene.positions[tri.v[e]])));
        const double area = double(scene.triangleArea(t));
        m.totalArea += area;
        m.longestEdge = std::max(m.longestEdge, longest);
        if (!(longest > m.edgeLimit)) continue;
        ++m.coarseTriangles;
        m.coarseArea += area;
        for (uint32_t v : tri.v) {
            m.coarseVertices += !counted[v];
            counted[v] = 1;
        }
    }
    return m;
}

}  // namespace qsgi
