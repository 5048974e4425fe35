// Impact count (docs/design.md §5): E_τ = Σ Φ / A_τ over the impacts on triangle τ; a vertex takes the
// mean E_τ of its non-degenerate triangles. Only impacts on the side the triangle's vertex
// normals face count, so E is the irradiance "on the side the vertex normal faces" (docs/design.md §2),
// as for the other estimators. With afterFirstBounce (--direct exact) the segments of bounce 0 —
// the emission and with it the first impact — count nowhere: direct light is computed apart.
#pragma once

#include <vector>

#include "estimate/fixed_point_power.h"
#include "estimate/vertex_radiosity.h"
#include "trace/ray_cache.h"

namespace qsgi {

class ImpactCount {
public:
    explicit ImpactCount(const Scene& scene, bool afterFirstBounce = false);

    // Recomputes the triangle sums from every segment of the cache.
    void accumulate(const RayCache& cache);
    // Incremental form: removes or adds the contribution of some segments (exact, fixed point).
    void add(const Segment& s, const PowerQuantizer& q);
    void subtract(const Segment& s, const PowerQuantizer& q);

    // Triangle areas and facing follow the scene's current pose (all, or the given triangles).
    void updateGeometry(const Scene& scene);
    void updateGeometry(const Scene& scene, const std::vector<uint32_t>& triangles);
    VertexRadiosity estimate(const Scene& scene, const PowerQuantizer& q) const;
    // The given vertices' irradiance, and every vertex's radiosity, in `out` (an update).
    void estimateAt(const Scene& scene, const PowerQuantizer& q, const std::vector<uint32_t>& vertices,
                    VertexRadiosity& out) const;

    uint32_t degenerateTriangles() const { return degenerate_; }
    const std::vector<PowerSum>& triangleSums() const { return sums_; }

private:
    bool counts(const Segment& s) const;
    Vec3f vertexIrradiance(uint32_t v, const PowerQuantizer& q) const;

    std::vector<PowerSum> sums_;
    std::vector<Vec3f> frontNormal_;  // geometric normal flipped to the vertex normals' side
    std::vector<float> area_;
    // The triangles around each vertex, in increasing order (CSR): a vertex's mean is summed in
    // the order a whole-scene pass sums it, so an update gives the same bits.
    std::vector<uint32_t> vertexTrianglesBegin_, vertexTriangles_;
    uint32_t degenerate_ = 0;
    bool afterFirstBounce_;
};

}  // namespace qsgi
