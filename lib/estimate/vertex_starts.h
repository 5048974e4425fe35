// Where each vertex's shadow and gather rays leave from, and along which normal (docs/design.md
// §5.1): the disc regions' start point s_v (vertexRayStart) and n_v, as of the pose they were last
// refreshed for. DiscRegions owns the rule and keeps it current across moves; this is the second
// pass's copy, so that a frame can tell which vertices' rays now leave from elsewhere.
#pragma once

#include <cstdint>
#include <vector>

#include "estimate/disc_regions.h"
#include "scene/scene.h"

namespace qsgi {

class VertexStarts {
public:
    // Every vertex, from regions of the scene's current pose.
    void refreshAll(const Scene& scene, const DiscRegions& regions);
    // The given vertices only; returns those whose start or normal changed (in the given order).
    std::vector<uint32_t> refresh(const Scene& scene, const DiscRegions& regions, const std::vector<uint32_t>& vertices);

    const Vec3f& point(uint32_t v) const { return points_[v]; }
    const Vec3f& normal(uint32_t v) const { return normals_[v]; }
    size_t size() const { return points_.size(); }

private:
    std::vector<Vec3f> points_, normals_;
};

}  // namespace qsgi
