#include "estimate/point_grid.h"

#include <algorithm>
#include <cmath>

namespace qsgi {

PointGrid::PointGrid(const std::vector<Vec3f>& points, float cellSize) {
    for (const Vec3f& p : points) bounds_.extend(p);
    if (points.empty() || bounds_.empty()) return;
    const Vec3f extent = bounds_.diagonal();
    for (int a = 0; a < 3; ++a) {
        const float want = cellSize > 0 ? std::ceil(extent[a] / cellSize) : 1.0f;
        n_[a] = std::isfinite(want) ? std::clamp(int(want), 1, kMaxCellsPerAxis) : 1;
        inverseCell_[a] = extent[a] > 0 ? float(n_[a]) / extent[a] : 0.0f;
    }
    auto cellOf = [&](const Vec3f& p) {
        size_t index = 0;
        for (int a = 2; a >= 0; --a) {
            const int c = std::clamp(int((p[a] - bounds_.lower[a]) * inverseCell_[a]), 0, n_[a] - 1);
            index = index * size_t(n_[a]) + size_t(c);
        }
        return index;
    };
    // A counting sort by cell: the points of a cell keep their input order.
    const size_t cells = size_t(n_[0]) * size_t(n_[1]) * size_t(n_[2]);
    std::vector<uint32_t> cellOfPoint(points.size());
    cellStart_.assign(cells + 1, 0);
    for (size_t i = 0; i < points.size(); ++i) {
        cellOfPoint[i] = uint32_t(cellOf(points[i]));
        ++cellStart_[cellOfPoint[i] + 1];
    }
    for (size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
    order_.resize(points.size());
    std::vector<uint32_t> next(cellStart_.begin(), cellStart_.end() - 1);
    for (size_t i = 0; i < points.size(); ++i) order_[next[cellOfPoint[i]]++] = uint32_t(i);
}

}  // namespace qsgi
