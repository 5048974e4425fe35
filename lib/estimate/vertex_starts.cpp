#include "estimate/vertex_starts.h"

#include <cstring>

namespace qsgi {

void VertexStarts::refreshAll(const Scene& scene, const DiscRegions& regions) {
    points_.resize(scene.vertexCount());
    normals_.resize(scene.vertexCount());
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        points_[v] = vertexRayStart(scene, regions[v], v);
        normals_[v] = scene.normals[v];
    }
}

std::vector<uint32_t> VertexStarts::refresh(const Scene& scene, const DiscRegions& regions, const std::vector<uint32_t>& vertices) {
    std::vector<uint32_t> changed;
    for (uint32_t v : vertices) {
        const Vec3f point = vertexRayStart(scene, regions[v], v);
        const Vec3f& normal = scene.normals[v];
        // Bitwise: the rays are the same only if they start from the very same floats.
        if (std::memcmp(&point, &points_[v], sizeof(Vec3f)) != 0 || std::memcmp(&normal, &normals_[v], sizeof(Vec3f)) != 0)
            changed.push_back(v);
        points_[v] = point;
        normals_[v] = normal;
    }
    return changed;
}

}  // namespace qsgi
