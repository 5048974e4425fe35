// Which tracked segments pass near a box, and which hit a given triangle (docs/design.md §6.2 and
// §6.5): what a frame searches instead of every tracked segment. A uniform grid over the envelope
// lists, per cell, the segments passing through it (with their extension past the impact): rule
// (b)'s candidates in the movers' new bounds, and the segments near the discs an update
// recomputes. Per dynamic triangle, the segments that hit it: rule (a).
//
// An entry is a SegmentRef packed in 4 bytes (SegmentRefLayout): the grid lists each tracked
// segment in a few cells, and its entries are a large part of the tracked state. Entries are never
// removed one by one: a rewritten path's old entries go stale (their generation is no longer
// their record's), are skipped and dropped by the queries that pass them, and are swept out
// everywhere once the grid holds half again as many entries as after its last sweep. Whether an
// entry is live is its owner's answer (TrackedPaths), passed in as `isLive`.
#pragma once

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <unordered_map>
#include <vector>

#include "util/modest_growth.h"
#include "util/vecmath.h"

namespace qsgi {

// A tracked segment: its path's slot (SlottedPathStore), its place among the path's tracked
// segments, and the generation it was written in.
struct SegmentRef {
    uint32_t slot = 0, place = 0, generation = 0;
};
using PackedRef = uint32_t;

// How a SegmentRef fits in 32 bits: as many bits for the slot as the slots need; for the place,
// room for twice the longest path (and at least 32 places) — a retrace that outgrows it renumbers
// with a wider layout; the rest, up to 8, for the generation, whose limit (generations()) is when
// the owner renumbers.
class SegmentRefLayout {
public:
    SegmentRefLayout() = default;
    SegmentRefLayout(size_t slots, uint32_t longestPath);

    PackedRef pack(const SegmentRef& r) const { return r.slot << slotShift_ | r.place << generationBits_ | r.generation; }
    SegmentRef unpack(PackedRef p) const {
        return {p >> slotShift_, (p >> generationBits_) & placeMask_, p & ((1u << generationBits_) - 1)};
    }
    // Whether a path of that many tracked segments has a place for each.
    bool holds(uint32_t pathLength) const { return pathLength <= placeMask_ + 1; }
    uint32_t generations() const { return 1u << generationBits_; }

private:
    uint32_t slotShift_ = 16, placeMask_ = 0xFF, generationBits_ = 8;
};

class SegmentIndex {
public:
    SegmentIndex() = default;
    // bounds: the region queries ask about; cellSize: the target cell edge (at most
    // maxCellsPerAxis cells along any axis); slots: how many tracked paths the references name.
    SegmentIndex(const Bounds3f& bounds, float cellSize, const SegmentRefLayout& layout, size_t slots,
                 int maxCellsPerAxis = 64);

    const SegmentRefLayout& layout() const { return layout_; }

    // Listing the part [0, end] of the ray o + t·d (end may be infinite) takes two steps: the
    // cells it passes (appended to `cells`; read-only, so threads can find them in parallel),
    // then listing the reference in them.
    void cellsOf(const Vec3f& origin, const Vec3f& direction, double end, std::vector<uint32_t>& cells) const;
    // Lists a batch of segments: forEach(emit) calls emit(ref, cells, cellCount) for each, in
    // order. The cells are filled in parallel by shards of cells, each taking its entries in
    // batch order whatever the thread count, so forEach runs once per shard, concurrently.
    template <class ForEach>
    void list(ForEach&& forEach);
    // Lists a segment on the (dynamic) triangle it hit.
    void listOnTriangle(uint32_t triangle, PackedRef ref) { pushBackModestly(byTriangle_[triangle], ref); }

    // Calls visit(ref) once for every live segment listed in a cell that overlaps one of the
    // boxes, in the grid's order, and drops the stale entries of those cells on the way (the
    // order of the rest is kept): calls must not overlap.
    template <class IsLive, class Visit>
    void visitNear(const std::vector<Bounds3f>& boxes, IsLive&& isLive, Visit&& visit);
    // Calls visit(ref) for every live segment listed on the triangle and drops the stale ones.
    // Returns how many entries it read, stale ones included.
    template <class IsLive, class Visit>
    size_t visitListedOn(uint32_t triangle, IsLive&& isLive, Visit&& visit);
    // How many live segments are listed on the triangles.
    template <class IsLive>
    uint64_t countListedOn(const std::vector<uint32_t>& triangles, IsLive&& isLive) const;

    // Whether stale entries are worth a sweep, and the sweep: every cell (in parallel: isLive
    // must be safe to call from several threads) and every triangle's list. The cells keep their
    // capacity: the next retraces fill them again.
    bool wantsSweep() const { return 2 * entries_ > 3 * entriesAfterSweep_; }
    template <class IsLive>
    void sweep(IsLive&& isLive);
    // Renumbering: every entry becomes rewrite(ref, out) ? out : dropped, in the new layout.
    template <class Rewrite>
    void rewriteAll(const SegmentRefLayout& layout, Rewrite&& rewrite);

    size_t bytes() const;

private:
    bool cellRange(const Bounds3f& box, int lo[3], int hi[3]) const;
    size_t cellIndex(int x, int y, int z) const { return (size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]) + size_t(x); }
    // Keeps the entries of `list` for which keep(ref) holds, in order; returns how many it dropped.
    template <class Keep>
    static size_t filter(std::vector<PackedRef>& list, Keep&& keep) {
        size_t kept = 0;
        for (PackedRef r : list)
            if (keep(r)) list[kept++] = r;
        const size_t dropped = list.size() - kept;
        list.resize(kept);
        return dropped;
    }

    Bounds3f bounds_;
    Vec3f cellSize_{1.0f}, inverseCellSize_{1.0f};
    int n_[3] = {0, 0, 0};
    SegmentRefLayout layout_;
    size_t slots_ = 0;
    std::vector<std::vector<PackedRef>> cells_;
    size_t entries_ = 0, entriesAfterSweep_ = 0;  // in the cells, stale ones included
    // Per dynamic triangle hit by a tracked segment: rule (a).
    std::unordered_map<uint32_t, std::vector<PackedRef>> byTriangle_;
};

template <class ForEach>
void SegmentIndex::list(ForEach&& forEach) {
    const uint32_t shards = uint32_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    std::vector<size_t> listed(shards, 0);
    tbb::parallel_for(uint32_t(0), shards, [&](uint32_t shard) {
        forEach([&](PackedRef ref, const uint32_t* cells, size_t cellCount) {
            for (size_t c = 0; c < cellCount; ++c)
                if (cells[c] % shards == shard) {
                    pushBackModestly(cells_[cells[c]], ref);
                    ++listed[shard];
                }
        });
    });
    for (size_t n : listed) entries_ += n;
}

template <class IsLive, class Visit>
void SegmentIndex::visitNear(const std::vector<Bounds3f>& boxes, IsLive&& isLive, Visit&& visit) {
    std::vector<uint8_t> marked(cells_.size(), 0);
    for (const Bounds3f& box : boxes) {
        int lo[3], hi[3];
        if (!cellRange(box, lo, hi)) continue;
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) marked[cellIndex(x, y, z)] = 1;
    }
    // A segment is listed in every cell it passes: one bit per (slot, place) keeps it once,
    // without sorting what may be millions of entries; places past the 64 bits are sorted.
    std::vector<uint64_t> seen(slots_, 0);
    std::vector<PackedRef> deep;
    for (size_t c = 0; c < cells_.size(); ++c) {
        if (!marked[c]) continue;
        entries_ -= filter(cells_[c], [&](PackedRef p) {
            if (!isLive(p)) return false;
            const SegmentRef r = layout_.unpack(p);
            if (r.place >= 64) {
                deep.push_back(p);
            } else if (!(seen[r.slot] >> r.place & 1)) {
                seen[r.slot] |= uint64_t(1) << r.place;
                visit(p);
            }
            return true;
        });
    }
    std::sort(deep.begin(), deep.end());
    deep.erase(std::unique(deep.begin(), deep.end()), deep.end());
    for (PackedRef p : deep) visit(p);
}

template <class IsLive, class Visit>
size_t SegmentIndex::visitListedOn(uint32_t triangle, IsLive&& isLive, Visit&& visit) {
    const auto list = byTriangle_.find(triangle);
    if (list == byTriangle_.end()) return 0;
    const size_t read = list->second.size();
    filter(list->second, [&](PackedRef p) {
        if (!isLive(p)) return false;
        visit(p);
        return true;
    });
    return read;
}

template <class IsLive>
uint64_t SegmentIndex::countListedOn(const std::vector<uint32_t>& triangles, IsLive&& isLive) const {
    uint64_t n = 0;
    for (uint32_t t : triangles)
        if (const auto list = byTriangle_.find(t); list != byTriangle_.end())
            for (PackedRef p : list->second) n += isLive(p);
    return n;
}

template <class IsLive>
void SegmentIndex::sweep(IsLive&& isLive) {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t c = range.begin(); c != range.end(); ++c) filter(cells_[c], isLive);
    });
    entries_ = 0;
    for (const auto& cell : cells_) entries_ += cell.size();
    entriesAfterSweep_ = entries_;
    for (auto& [triangle, list] : byTriangle_) filter(list, isLive);
}

template <class Rewrite>
void SegmentIndex::rewriteAll(const SegmentRefLayout& layout, Rewrite&& rewrite) {
    auto rewriteList = [&](std::vector<PackedRef>& list) {
        size_t kept = 0;
        for (PackedRef p : list)
            if (PackedRef out; rewrite(p, out)) list[kept++] = out;
        list.resize(kept);
    };
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t c = range.begin(); c != range.end(); ++c) rewriteList(cells_[c]);
    });
    for (auto& [triangle, list] : byTriangle_) rewriteList(list);
    layout_ = layout;
    entries_ = 0;
    for (const auto& cell : cells_) entries_ += cell.size();
    entriesAfterSweep_ = entries_;
}

}  // namespace qsgi
