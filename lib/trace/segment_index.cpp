#include "trace/segment_index.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace qsgi {

namespace {
// Bits needed for the values [0, n).
int bitsFor(uint64_t n) {
    int bits = 0;
    while (bits < 64 && (uint64_t(1) << bits) < n) ++bits;
    return bits;
}
}  // namespace

SegmentRefLayout::SegmentRefLayout(size_t slots, uint32_t longestPath) {
    const int needed = bitsFor(longestPath);
    const int placeBits = std::max(needed + 1, 5);
    const int slotBits = bitsFor(slots);
    // The generation takes what the slot leaves, from 4 bits to 8; slots beyond that go to banks.
    const int generationBits = std::clamp(32 - placeBits - slotBits, 4, 8);
    const int lowSlotBits = std::min(slotBits, 32 - placeBits - generationBits);
    generationBits_ = uint32_t(generationBits);
    placeMask_ = (1u << placeBits) - 1;
    slotShift_ = uint32_t(placeBits + generationBits);
    lowSlotBits_ = uint32_t(lowSlotBits);
    lowSlotMask_ = uint32_t((uint64_t(1) << lowSlotBits) - 1);
    banks_ = uint32_t(1) << (slotBits - lowSlotBits);
}

SegmentIndex::SegmentIndex(const Bounds3f& bounds, float cellSize, const SegmentRefLayout& layout, size_t slots,
                           int maxCellsPerAxis)
    : bounds_(bounds), layout_(layout), slots_(slots) {
    if (bounds.empty()) return;
    const Vec3f extent = bounds.diagonal();
    for (int a = 0; a < 3; ++a) {
        const float want = cellSize > 0 ? std::ceil(extent[a] / cellSize) : 1.0f;
        n_[a] = std::clamp(int(std::isfinite(want) ? want : 1.0f), 1, std::max(1, maxCellsPerAxis));
        cellSize_[a] = extent[a] > 0 ? extent[a] / float(n_[a]) : 1.0f;
        inverseCellSize_[a] = 1.0f / cellSize_[a];
    }
    cells_ = size_t(n_[0]) * size_t(n_[1]) * size_t(n_[2]);
    lists_.resize(cells_ * layout_.banks());
}

std::vector<uint8_t> SegmentIndex::cellsOverlapping(const std::vector<Bounds3f>& boxes) const {
    std::vector<uint8_t> marked(cells_, 0);
    for (const Bounds3f& box : boxes) {
        int lo[3], hi[3];
        if (!cellRange(box, lo, hi)) continue;
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) marked[cellIndex(x, y, z)] = 1;
    }
    return marked;
}

uint64_t SegmentIndex::entriesNear(const std::vector<Bounds3f>& boxes) const {
    const std::vector<uint8_t> marked = cellsOverlapping(boxes);
    uint64_t entries = 0;
    for (size_t c = 0; c < cells_; ++c)
        if (marked[c])
            for (uint32_t bank = 0; bank < layout_.banks(); ++bank) entries += lists_[c * layout_.banks() + bank].size();
    return entries;
}

bool SegmentIndex::cellRange(const Bounds3f& box, int lo[3], int hi[3]) const {
    if (cells_ == 0 || !box.overlaps(bounds_)) return false;
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::clamp(int(std::floor((box.lower[a] - bounds_.lower[a]) * inverseCellSize_[a])), 0, n_[a] - 1);
        hi[a] = std::clamp(int(std::floor((box.upper[a] - bounds_.lower[a]) * inverseCellSize_[a])), 0, n_[a] - 1);
    }
    return true;
}

void SegmentIndex::cellsOf(const Vec3f& origin, const Vec3f& direction, double end, std::vector<uint32_t>& cells) const {
    double t0 = 0, t1 = end;
    if (cells_ == 0 || !bounds_.clip(origin, direction, t0, t1)) return;
    // Pieces shorter than the smallest cell edge (so at most 2 cells along each axis, 8 in all),
    // each listed in the cells its (slightly padded) box overlaps that the ray itself passes
    // (their padded box clips it): conservative, with no floating-point cell walk to get wrong.
    // Most pieces pass diagonally: their box overlaps about a third more cells than they pass.
    const double step = 0.9 * double(std::min({cellSize_[0], cellSize_[1], cellSize_[2]}));
    const Vec3f pad(1e-4f * std::min({cellSize_[0], cellSize_[1], cellSize_[2]}));
    const size_t pieces = std::max<size_t>(1, size_t(std::ceil((t1 - t0) / step)));
    const Vec3d o(origin), d(direction);
    size_t last[8];
    int lastCount = 0;
    Vec3f from(o + d * t0);  // each piece starts where the previous one ended
    for (size_t i = 0; i < pieces; ++i) {
        const Vec3f to(o + d * (t0 + (t1 - t0) * double(i + 1) / double(pieces)));
        int lo[3], hi[3];
        bool inside = true;
        for (int a = 0; a < 3; ++a) {
            const float low = std::min(from[a], to[a]) - pad[a], high = std::max(from[a], to[a]) + pad[a];
            inside = inside && high >= bounds_.lower[a] && low <= bounds_.upper[a];
            lo[a] = std::clamp(int(std::floor((low - bounds_.lower[a]) * inverseCellSize_[a])), 0, n_[a] - 1);
            hi[a] = std::clamp(int(std::floor((high - bounds_.lower[a]) * inverseCellSize_[a])), 0, n_[a] - 1);
        }
        from = to;
        if (!inside) continue;
        size_t now[8];
        int nowCount = 0;
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    const size_t c = cellIndex(x, y, z);
                    if (nowCount < 8) now[nowCount++] = c;
                    // Consecutive pieces share cells: list the segment once per cell it enters.
                    if (std::find(last, last + lastCount, c) != last + lastCount) continue;
                    Bounds3f cell;
                    cell.lower = bounds_.lower + cellSize_ * Vec3f(float(x), float(y), float(z)) - pad;
                    cell.upper = bounds_.lower + cellSize_ * Vec3f(float(x + 1), float(y + 1), float(z + 1)) + pad;
                    double c0 = t0, c1 = t1;
                    if (cell.clip(origin, direction, c0, c1)) cells.push_back(uint32_t(c));
                }
        std::copy(now, now + nowCount, last);
        lastCount = nowCount;
    }
}

size_t SegmentIndex::countEntries() const {
    size_t n = 0;
    for (const auto& list : lists_) n += list.size();
    return n;
}

size_t SegmentIndex::bytes() const {
    size_t total = lists_.capacity() * sizeof(lists_[0]);
    for (const auto& list : lists_) total += list.capacity() * sizeof(uint32_t);
    // A node of the map: its key and list, and the next pointer; and the buckets.
    total += byTriangle_.bucket_count() * sizeof(void*);
    for (const auto& [key, list] : byTriangle_)
        total += sizeof(key) + sizeof(list) + sizeof(void*) + list.capacity() * sizeof(uint32_t);
    return total;
}

}  // namespace qsgi
