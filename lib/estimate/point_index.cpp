#include "estimate/point_index.h"

#include <flann/flann.hpp>

#include <cmath>
#include <limits>

namespace qsgi {

// The tree itself rather than flann::Index: anyWithin() hands it a result set of its own.
struct PointIndex::Tree {
    flann::Matrix<float> points;  // views PointIndex::points_, which outlives the tree
    flann::KDTreeSingleIndex<flann::L2<float>> index;
    Tree(float* data, size_t n) : points(data, n, 3), index(points, flann::KDTreeSingleIndexParams(12)) {
        index.buildIndex();
    }
};

PointIndex::PointIndex(std::vector<Vec3f> points) : points_(std::move(points)) {
    static_assert(sizeof(Vec3f) == 3 * sizeof(float), "FLANN reads points as packed float triples");
    if (!points_.empty()) tree_ = std::make_unique<Tree>(&points_[0].x, points_.size());
}

PointIndex::~PointIndex() = default;

size_t PointIndex::liveSize() const { return tree_ ? tree_->index.size() : 0; }

void PointIndex::remove(size_t i) {
    if (tree_ && i < points_.size()) tree_->index.removePoint(i);
}

float PointIndex::distanceSquared(const Vec3f& a, const Vec3f& b) { return flann::L2<float>()(&a.x, &b.x, 3); }

namespace {
const flann::SearchParams kExact(flann::FLANN_CHECKS_UNLIMITED, 0.0f, true);

// Collects nothing: notes whether a point within the limit was seen, and then reports a negative
// worst distance so the tree visits nothing more.
class FirstWithin : public flann::ResultSet<float> {
public:
    FirstWithin(float limit, const std::function<bool(size_t)>& accept)
        // The tree prunes against the bound with its own rounding; a margin keeps a point lying
        // exactly at the limit from being pruned, and addPoint() applies the exact test.
        : limit_(limit), bound_(std::nextafter(limit * (1.0f + 0x1p-10f), std::numeric_limits<float>::infinity())),
          accept_(accept) {}
    bool full() const override { return found_; }
    void addPoint(float distance, size_t index) override {
        found_ = found_ || (distance <= limit_ && (!accept_ || accept_(index)));
    }
    float worstDist() const override { return found_ ? -1.0f : bound_; }
    bool found() const { return found_; }

private:
    float limit_, bound_;
    const std::function<bool(size_t)>& accept_;
    bool found_ = false;
};
}  // namespace

void PointIndex::nearest(const Vec3f& p, size_t count, std::vector<size_t>& indices, std::vector<float>& d2) const {
    // With removed points FLANN fills a request beyond the live ones with placeholders.
    count = std::min(count, liveSize());
    indices.assign(count, 0);
    d2.assign(count, 0);
    if (count == 0) return;
    flann::Matrix<float> query(const_cast<float*>(&p.x), 1, 3);
    flann::Matrix<size_t> idx(indices.data(), 1, count);
    flann::Matrix<float> dst(d2.data(), 1, count);
    const size_t found = size_t(tree_->index.knnSearch(query, idx, dst, count, kExact));
    indices.resize(found);
    d2.resize(found);
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

bool PointIndex::anyWithin(const Vec3f& p, float radiusSquared, const std::function<bool(size_t)>& accept) const {
    if (!tree_ || tree_->index.size() == 0 || !(radiusSquared >= 0)) return false;
    FirstWithin result(radiusSquared, accept);
    tree_->index.findNeighbors(result, &p.x, kExact);
    return result.found();
}

}  // namespace qsgi
