// The impact points of the ray cache in a kd-tree (PointIndex), each with the segment it ends.
#pragma once

#include <vector>

#include "estimate/point_index.h"
#include "trace/ray_cache.h"

namespace qsgi {

class ImpactIndex : public PointIndex {
public:
    explicit ImpactIndex(const RayCache& cache) : PointIndex(impactPoints(cache)), segments_(impactSegments(cache)) {}
    uint32_t segment(size_t i) const { return segments_[i]; }  // index into cache.segments

private:
    static std::vector<Vec3f> impactPoints(const RayCache& cache);
    static std::vector<uint32_t> impactSegments(const RayCache& cache);
    std::vector<uint32_t> segments_;
};

}  // namespace qsgi
