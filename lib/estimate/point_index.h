// A FLANN kd-tree over 3-D points (exact: one single-index tree, eps = 0, unlimited checks).
// Photon-map queries, DETP's FLANN candidate search and the accuracy tool's border search use it.
// Points can be removed after the build (searches skip them); none can be added.
#pragma once

#include <functional>
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

    // Every point given, removed or not: the range of point() and of the indices searches return.
    size_t size() const { return points_.size(); }
    // The points searches can still return.
    size_t liveSize() const;
    const Vec3f& point(size_t i) const { return points_[i]; }

    // Point i is left out of every later search (its index stays valid). Removing it again does
    // nothing. Not thread-safe: no search may run meanwhile.
    void remove(size_t i);

    // The `count` nearest live points to p, nearest first (at most liveSize()). Thread-safe.
    void nearest(const Vec3f& p, size_t count, std::vector<size_t>& indices, std::vector<float>& distancesSquared) const;
    // Every live point within sqrt(radiusSquared) of p, nearest first. Thread-safe.
    void withinRadius(const Vec3f& p, float radiusSquared, std::vector<size_t>& indices,
                      std::vector<float>& distancesSquared) const;
    // Whether some live point lies at distanceSquared() ≤ radiusSquared from p; the search stops at
    // the first one found. Thread-safe.
    // accept, if given, must also hold for the point (by index).
    bool anyWithin(const Vec3f& p, float radiusSquared, const std::function<bool(size_t)>& accept = {}) const;
    // FLANN's own metric, for index-free references that must rank exactly as the tree does.
    static float distanceSquared(const Vec3f& a, const Vec3f& b);

private:
    std::vector<Vec3f> points_;
    struct Tree;
    std::unique_ptr<Tree> tree_;
};

}  // namespace qsgi
