// A uniform grid over a set of points, built in linear time: which points may lie within a
// distance of a query point. Built once per frame over what a frame changed (the photon map's
// removed or added impacts), where a kd-tree's build would cost more than the queries it saves.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

class PointGrid {
public:
    // cellSize: the target cell edge (at most kMaxCellsPerAxis cells along an axis).
    PointGrid(const std::vector<Vec3f>& points, float cellSize);

    // Calls visit(i) for every point i in the cells the ball (centre p, radius) overlaps: every
    // point within the radius, and some beyond it (the caller measures).
    template <typename Visit>
    void visitNear(const Vec3f& p, float radius, Visit&& visit) const {
        if (order_.empty()) return;
        // Padded past the rounding of the cell arithmetic, so no point within the radius is missed.
        const float reach = radius * 1.0001f + 1e-6f * std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z), 1.0f});
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            const float low = (p[a] - reach - bounds_.lower[a]) * inverseCell_[a];
            const float high = (p[a] + reach - bounds_.lower[a]) * inverseCell_[a];
            if (!(high >= 0) || !(low < float(n_[a]))) return;  // NaN-safe: outside, or no number
            lo[a] = low > 0 ? int(low) : 0;
            hi[a] = high < float(n_[a] - 1) ? int(high) : n_[a] - 1;
        }
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y) {
                const size_t row = (size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]);
                for (uint32_t i = cellStart_[row + size_t(lo[0])]; i < cellStart_[row + size_t(hi[0]) + 1]; ++i) visit(order_[i]);
            }
    }

    static constexpr int kMaxCellsPerAxis = 128;

private:
    Bounds3f bounds_;
    Vec3f inverseCell_{0.0f};
    int n_[3] = {1, 1, 1};
    std::vector<uint32_t> cellStart_;  // per cell (x fastest), into order_; one past the end last
    std::vector<uint32_t> order_;      // point indices by cell
};

}  // namespace qsgi
