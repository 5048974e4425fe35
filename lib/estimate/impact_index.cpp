#include "estimate/impact_index.h"

namespace qsgi {

std::vector<Vec3f> ImpactIndex::impactPoints(const std::vector<Segment>& segments, bool afterFirstBounce) {
    std::vector<Vec3f> points;
    for (const Segment& s : segments)
        if (indexed(s, afterFirstBounce)) points.push_back(s.impactPoint());
    return points;
}

std::vector<uint32_t> ImpactIndex::impactSegments(const std::vector<Segment>& segments, bool afterFirstBounce) {
    std::vector<uint32_t> ids;
    for (size_t i = 0; i < segments.size(); ++i)
        if (indexed(segments[i], afterFirstBounce)) ids.push_back(uint32_t(i));
    return ids;
}

}  // namespace qsgi
