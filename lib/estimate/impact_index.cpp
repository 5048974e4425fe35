#include "estimate/impact_index.h"

namespace qsgi {

std::vector<Vec3f> ImpactIndex::impactPoints(const RayCache& cache) {
    std::vector<Vec3f> points;
    for (const Segment& s : cache.segments)
        if (s.hasImpact()) points.push_back(s.impactPoint());
    return points;
}

std::vector<uint32_t> ImpactIndex::impactSegments(const RayCache& cache) {
    std::vector<uint32_t> ids;
    for (size_t i = 0; i < cache.segments.size(); ++i)
        if (cache.segments[i].hasImpact()) ids.push_back(uint32_t(i));
    return ids;
}

}  // namespace qsgi
