// A uniform grid over the envelope that lists, per cell, the tracked segments passing through it
// (with their extension). It answers "which segments pass near this box" without testing every
// cached segment: the moved objects' new bounds (segments they may now block) and the discs an
// update recomputes. Entries are never removed one by one: each carries its path's generation,
// entries of a path that was retraced since are stale, skipped, and swept out once they are a
// quarter of the live ones.
#pragma once

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "util/modest_growth.h"
#include "util/vecmath.h"

namespace qsgi {

// Eight bytes: the grid lists each tracked segment in about four cells, and its entries are most of
// the tracked state. A path's generation wraps at 2^16 retraces; TrackedPaths renumbers every
// path before one would (TrackedPaths::renumber).
struct SegmentRef {
    uint32_t path = 0;
    uint16_t generation = 0;
    uint16_t bounce = 0;  // a segment's bounce is below kMaxBounces = 2^16
    bool operator<(const SegmentRef& o) const { return path < o.path || (path == o.path && bounce < o.bounce); }
    bool operator==(const SegmentRef& o) const { return path == o.path && bounce == o.bounce; }
};

class SegmentGrid {
public:
    SegmentGrid() = default;
    // bounds: the region queries ask about; cellSize: the target cell edge (at most
    // maxCellsPerAxis cells along any axis).
    SegmentGrid(const Bounds3f& bounds, float cellSize, int maxCellsPerAxis = 64);

    // Listing the part [0, end] of the ray o + t·d (end may be infinite) in every cell it passes
    // takes two steps: the cells the ray passes (appended to `cells`; read-only, so threads can
    // find them in parallel), then listing ref in them.
    void cellsOf(const Vec3f& origin, const Vec3f& direction, double end, std::vector<uint32_t>& cells) const;
    void insertInto(const uint32_t* cells, size_t count, const SegmentRef& ref) {
        for (size_t i = 0; i < count; ++i) pushBackModestly(cells_[cells[i]], ref);
    }
    // The same for the cells of one shard only (cell % shards == shard): shards can be filled
    // in parallel, each cell still in the order its entries come.
    void insertIntoShard(const uint32_t* cells, size_t count, const SegmentRef& ref, uint32_t shard, uint32_t shards) {
        for (size_t i = 0; i < count; ++i)
            if (cells[i] % shards == shard) pushBackModestly(cells_[cells[i]], ref);
    }
    // Calls visit(ref) for every live entry (isLive(ref)) of every cell that overlaps one of the
    // boxes, as often as it is listed in such cells, and drops the stale entries of those cells
    // on the way (the order of the rest is kept). Returns how many it dropped.
    template <typename IsLive, typename Visit>
    size_t visitLiveCells(const std::vector<Bounds3f>& boxes, IsLive&& isLive, Visit&& visit) {
        std::vector<uint8_t> marked(cells_.size(), 0);
        for (const Bounds3f& box : boxes) {
            int lo[3], hi[3];
            if (!cellRange(box, lo, hi)) continue;
            for (int z = lo[2]; z <= hi[2]; ++z)
                for (int y = lo[1]; y <= hi[1]; ++y)
                    for (int x = lo[0]; x <= hi[0]; ++x) marked[cellIndex(x, y, z)] = 1;
        }
        size_t dropped = 0;
        for (size_t c = 0; c < cells_.size(); ++c) {
            if (!marked[c]) continue;
            std::vector<SegmentRef>& cell = cells_[c];
            size_t kept = 0;
            for (const SegmentRef& r : cell) {
                if (!isLive(r)) continue;
                cell[kept++] = r;
                visit(r);
            }
            dropped += cell.size() - kept;
            cell.resize(kept);
        }
        return dropped;
    }
    // Drops every entry (the cells stay).
    void clear() {
        for (auto& cell : cells_) std::vector<SegmentRef>().swap(cell);
    }
    // Drops stale entries everywhere, cells in parallel (isLive must be safe to call from
    // several threads). The cells keep their capacity: the next retraces fill them again.
    template <typename IsLive>
    void sweep(IsLive isLive) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_.size(), 64), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t c = range.begin(); c != range.end(); ++c) {
                std::vector<SegmentRef>& cell = cells_[c];
                size_t kept = 0;
                for (const SegmentRef& r : cell)
                    if (isLive(r)) cell[kept++] = r;
                cell.resize(kept);
            }
        });
    }

    size_t bytes() const;

private:
    bool cellRange(const Bounds3f& box, int lo[3], int hi[3]) const;
    size_t cellIndex(int x, int y, int z) const { return (size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]) + size_t(x); }

    Bounds3f bounds_;
    Vec3f cellSize_{1.0f}, inverseCellSize_{1.0f};
    int n_[3] = {0, 0, 0};
    std::vector<std::vector<SegmentRef>> cells_;
};

}  // namespace qsgi
