// A FLANN kd-tree over the impact points of the ray cache (exact: one single-index tree, eps = 0,
// unlimited checks). The photon map's k-NN queries and DETP's approximate FLANN candidate search
// both use it.
#pragma once

#include <memory>
#include <vector>

#include "trace/ray_cache.h"

namespace qsgi {

class ImpactIndex {
public:
    explicit ImpactIndex(const RayCache& cache);
    ~ImpactIndex();
    ImpactIndex(const ImpactIndex&) = delete;
    ImpactIndex& operator=(const ImpactIndex&) = delete;

    size_t size() const { return points_.size(); }
    const Vec3f& point(size_t i) const { return points_[i]; }
    uint32_t segment(size_t i) const { return segments_[i]; }  // index into cache.segments

    // The `count` nearest impacts to p, nearest first (count ≤ size()). Thread-safe.
    void nearest(const Vec3f& p, size_t count, std::vector<size_t>& indices, std::vector<float>& distancesSquared) const;
    // Every impact within sqrt(radiusSquared) of p, nearest first. Thread-safe.
    void withinRadius(const Vec3f& p, float radiusSquared, std::vector<size_t>& indices,
                      std::vector<float>& distancesSquared) const;
    // FLANN's own metric, for index-free references that must rank exactly as the tree does.
    static float distanceSquared(const Vec3f& a, const Vec3f& b);

private:
    std::vector<Vec3f> points_;
    std::vector<uint32_t> segments_;
    struct Tree;
    std::unique_ptr<Tree> tree_;
};

}  // namespace qsgi
