#include "estimate/point_index.h"

#include <flann/flann.hpp>

namespace qsgi {

struct PointIndex::Tree {
    flann::Matrix<float> points;  // views PointIndex::points_, which outlives the tree
    flann::Index<flann::L2<float>> index;
    Tree(float* data, size_t n) : points(data, n, 3), index(points, flann::KDTreeSingleIndexParams(12)) {
        index.buildIndex();
    }
};

PointIndex::PointIndex(std::vector<Vec3f> points) : points_(std::move(points)) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "FLANN reads points as packed float triples");
    if (!points_.empty()) tree_ = std::make_unique<Tree>(&points_[0].x, points_.size());
}

PointIndex::~PointIndex() = default;

float PointIndex::distanceSquared(const Vec3f& a, const Vec3f& b) { return flann::L2<float>()(&a.x, &b.x, 3); }

namespace {
const flann::SearchParams kExact(flann::FLANN_CHECKS_UNLIMITED, 0.0f, true);
}

void PointIndex::nearest(const Vec3f& p, size_t count, std::vector<size_t>& indices, std::vector<float>& d2) const {
    count = std::min(count, points_.size());
    indices.assign(count, 0);
    d2.assign(count, 0);
    if (count == 0) return;
    flann::Matrix<float> query(const_cast<float*>(&p.x), 1, 3);
    flann::Matrix<size_t> idx(indices.data(), 1, count);
    flann::Matrix<float> dst(d2.data(), 1, count);
    tree_->index.knnSearch(query, idx, dst, count, kExact);
}

void PointIndex::withinRadius(const Vec3f& p, float radiusSquared, std::vector<size_t>& indices,
                              std::vector<float>& d2) const {
    indices.clear();
    d2.clear();
    if (!tree_) return;
    std::vector<std::vector<size_t>> idx(1);
    std::vector<std::vector<float>> dst(1);
    flann::Matrix<float> query(const_cast<float*>(&p.x), 1, 3);
    tree_->index.radiusSearch(query, idx, dst, radiusSquared, kExact);
    indices.swap(idx[0]);
    d2.swap(dst[0]);
}

}  // namespace qsgi
