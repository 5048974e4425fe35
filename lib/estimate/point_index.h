// A FLANN kd-tree over 3-D points (exact: one single-index tree, eps = 0, unlimited checks).
// Photon-map queries, DETP's FLANN candidate search and the accuracy tool's border search use it.
#pragma once

#include <memory>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

class PointIndex {
public:
    explicit PointIndex(std::vector<Vec3f> points);
    ~PointIndex();
    PointIndex(const PointIndex&) = delete;
    PointIndex& operator=(const PointIndex&) = delete;

    size_t size() const { return points_.size(); }
    const Vec3f& point(size_t i) const { return points_[i]; }

    // The `count` nearest points to p, nearest first (at most size()). Thread-safe.
    void nearest(const Vec3f& p, size_t count, std::vector<size_t>& indices, std::vector<float>& distancesSquared) const;
    // Every point within sqrt(radiusSquared) of p, nearest first. Thread-safe.
    void withinRadius(const Vec3f& p, float radiusSquared, std::vector<size_t>& indices,
                      std::vector<float>& distancesSquared) const;
    // FLANN's own metric, for index-free references that must rank exactly as the tree does.
    static float distanceSquared(const Vec3f& a, const Vec3f& b);

private:
    std::vector<Vec3f> points_;
    struct Tree;
    std::unique_ptr<Tree> tree_;
};

}  // namespace qsgi
