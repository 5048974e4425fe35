// Impact count (DESIGN §5): E_τ = Σ Φ / A_τ over the impacts on triangle τ; a vertex takes the
// mean E_τ of its non-degenerate triangles. Only impacts on the side the triangle's vertex
// normals face count, so E is the irradiance "on the side the vertex normal faces" (DESIGN §2),
// as for the other estimators.
#pragma once

#include <vector>

#include "estimate/fixed_point_power.h"
#include "estimate/vertex_radiosity.h"
#include "trace/ray_cache.h"

namespace qsgi {

class ImpactCount {
public:
    explicit ImpactCount(const Scene& scene);

    // Recomputes the triangle sums from every segment of the cache.
    void accumulate(const RayCache& cache);
    // Incremental form: removes or adds the contribution of some segments (exact, fixed point).
    void add(const Segment& s, const PowerQuantizer& q);
    void subtract(const Segment& s, const PowerQuantizer& q);

    // Triangle areas and facing follow the scene's current pose.
    void updateGeometry(const Scene& scene);
    VertexRadiosity estimate(const Scene& scene, const PowerQuantizer& q) const;

    uint32_t degenerateTriangles() const { return degenerate_; }
    const std::vector<PowerSum>& triangleSums() const { return sums_; }

private:
    bool counts(const Segment& s) const;

    std::vector<PowerSum> sums_;
    std::vector<Vec3f> frontNormal_;  // geometric normal flipped to the vertex normals' side
    std::vector<float> area_;
    uint32_t degenerate_ = 0;
};

}  // namespace qsgi
