#include "estimate/morton_order.h"

#include <algorithm>
#include <numeric>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace qsgi {

namespace {
// Spreads the low 21 bits of x so that two zero bits separate each.
uint64_t spreadBits(uint64_t x) {
    x &= 0x1FFFFF;
    x = (x | x << 32) & 0x1F00000000FFFFull;
    x = (x | x << 16) & 0x1F0000FF0000FFull;
    x = (x | x << 8) & 0x100F00F00F00F00Full;
    x = (x | x << 4) & 0x10C30C30C30C30C3ull;
    x = (x | x << 2) & 0x1249249249249249ull;
    return x;
}
}  // namespace

std::vector<uint32_t> inputOrder(size_t n) {
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    return order;
}

std::vector<uint32_t> mortonOrder(const std::vector<Vec3f>& points) {
    Bounds3f b;
    for (const Vec3f& p : points) b.extend(p);
    const Vec3f size = b.diagonal();
    const float scale = maxComponent(size) > 0 ? float((1 << 21) - 1) / maxComponent(size) : 0.0f;
    std::vector<std::pair<uint64_t, uint32_t>> keyed(points.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3f q = (points[i] - b.lower) * scale;
            keyed[i] = {spreadBits(uint64_t(q.x)) | spreadBits(uint64_t(q.y)) << 1 | spreadBits(uint64_t(q.z)) << 2, uint32_t(i)};
        }
    });
    // (key, index) pairs are unique, so the parallel sort's result does not depend on scheduling.
    tbb::parallel_sort(keyed.begin(), keyed.end());
    std::vector<uint32_t> order(points.size());
    for (size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
    return order;
}

}  // namespace qsgi
