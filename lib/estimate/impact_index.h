// The impact points of a ray cache's decoded segments in a kd-tree (PointIndex), each with the segment it ends.
#pragma once

#include <vector>

#include "estimate/point_index.h"
#include "trace/ray_cache.h"

namespace qsgi {

class ImpactIndex : public PointIndex {
public:
    explicit ImpactIndex(const std::vector<Segment>& segments)
        : PointIndex(impactPoints(segments)), segments_(impactSegments(segments)) {}
    uint32_t segment(size_t i) const { return segments_[i]; }  // index into the segments given

private:
    static std::vector<Vec3f> impactPoints(const std::vector<Segment>& segments);
    static std::vector<uint32_t> impactSegments(const std::vector<Segment>& segments);
    std::vector<uint32_t> segments_;
};

}  // namespace qsgi
