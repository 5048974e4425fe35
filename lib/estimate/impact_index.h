// The impact points of a ray cache's decoded segments in a kd-tree (PointIndex), each with the segment it ends.
// afterFirstBounce: the impacts of bounce-0 segments are left out (their segments keep their
// indexes in the list given).
#pragma once

#include <vector>

#include "estimate/point_index.h"
#include "trace/ray_cache.h"

namespace qsgi {

class ImpactIndex : public PointIndex {
public:
    explicit ImpactIndex(const std::vector<Segment>& segments, bool afterFirstBounce = false)
        : PointIndex(impactPoints(segments, afterFirstBounce)), segments_(impactSegments(segments, afterFirstBounce)) {}
    uint32_t segment(size_t i) const { return segments_[i]; }  // index into the segments given

private:
    static bool indexed(const Segment& s, bool afterFirstBounce) {
        return s.hasImpact() && !(afterFirstBounce && !s.scattered);
    }
    static std::vector<Vec3f> impactPoints(const std::vector<Segment>& segments, bool afterFirstBounce);
    static std::vector<uint32_t> impactSegments(const std::vector<Segment>& segments, bool afterFirstBounce);
    std::vector<uint32_t> segments_;
};

}  // namespace qsgi
