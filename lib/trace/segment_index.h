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
// everywhere once the grid holds half again as many entries as after its last sweep. Whether a
// reference is live is its owner's answer (TrackedPaths), passed in as `isLive`; the packing is
// this file's alone.
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

// How a SegmentRef fits in a 4-byte entry. The place gets room for twice the longest path (and at
// least 32 places): a retrace that outgrows it renumbers with a wider layout. The generation gets
// up to 8 bits (generations(): the owner renumbers before one would wrap) and never fewer than 4;
// the slot the rest. When the slots need more bits than that leaves (hundreds of millions of
// tracked paths), their high bits pick one of several banks, each with its own lists, and the
// entry holds the low bits.
class SegmentRefLayout {
public:
    SegmentRefLayout() = default;
    SegmentRefLayout(size_t slots, uint32_t longestPath);

    uint32_t banks() const { return banks_; }
    uint32_t bankOf(uint32_t slot) const { return slot >> lowSlotBits_; }
    uint32_t pack(const SegmentRef& r) const {
        return (r.slot & lowSlotMask_) << slotShift_ | r.place << generationBits_ | r.generation;
    }
    SegmentRef unpack(uint32_t entry, uint32_t bank) const {
        return {bank << lowSlotBits_ | entry >> slotShift_, (entry >> generationBits_) & placeMask_,
                entry & ((1u << generationBits_) - 1)};
    }
    // Whether a path of that many tracked segments has a place for each.
    bool holds(uint32_t pathLength) const { return pathLength <= placeMask_ + 1; }
    uint32_t generations() const { return 1u << generationBits_; }

private:
    uint32_t generationBits_ = 8, placeMask_ = 0xFF, slotShift_ = 16, lowSlotBits_ = 16, lowSlotMask_ = 0xFFFF;
    uint32_t banks_ = 1;
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
    void listOnTriangle(uint32_t triangle, const SegmentRef& ref) {
        pushBackModestly(byTriangle_[triangleKey(triangle, layout_.bankOf(ref.slot))], layout_.pack(ref));
    }

    // Calls visit(ref) once for every live segment (isLive(ref)) listed in a cell that overlaps
    // one of the boxes, in the grid's order, and drops the stale entries of those cells on the
    // way (the order of the rest is kept): calls must not overlap.
    template <class IsLive, class Visit>
    void visitNear(const std::vector<Bounds3f>& boxes, IsLive&& isLive, Visit&& visit);
    // The entries listed in the cells that overlap any of the boxes, stale ones and a segment's
    // several cells included: a bound on what visitNear visits, counted without reading an entry
    // (what the frame solver prices an update by before it does any of it).
    uint64_t entriesNear(const std::vector<Bounds3f>& boxes) const;
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
    // Everything listed so far is live (a new index): what wantsSweep measures against.
    void allLive() { entriesAfterSweep_ = entries_; }
    template <class IsLive>
    void sweep(IsLive&& isLive);
    // Renumbering: every live entry is kept at generation 0, in the new layout; the stale ones
    // are dropped. isLive answers in the old one.
    template <class IsLive>
    void renumber(const SegmentRefLayout& layout, IsLive&& isLive);

    size_t bytes() const;

private:
    bool cellRange(const Bounds3f& box, int lo[3], int hi[3]) const;
    // Per cell, 1 if it overlaps one of the boxes.
    std::vector<uint8_t> cellsOverlapping(const std::vector<Bounds3f>& boxes) const;
    size_t cellIndex(int x, int y, int z) const { return (size_t(z) * size_t(n_[1]) + size_t(y)) * size_t(n_[0]) + size_t(x); }
    // A cell's list in a bank, and the key of a triangle's.
    std::vector<uint32_t>& cellList(size_t cell, uint32_t bank) { return lists_[cell * layout_.banks() + bank]; }
    uint64_t triangleKey(uint32_t triangle, uint32_t bank) const { return uint64_t(triangle) * layout_.banks() + bank; }
    // Keeps the entries of a bank's list whose reference keep(ref) accepts, in order; returns
    // how many it dropped.
    template <class Keep>
    size_t filter(std::vector<uint32_t>& entries, uint32_t bank, Keep&& keep) const {
        size_t kept = 0;
        for (uint32_t e : entries)
            if (keep(layout_.unpack(e, bank))) entries[kept++] = e;
        const size_t dropped = entries.size() - kept;
        entries.resize(kept);
        return dropped;
    }
    size_t countEntries() const;

    Bounds3f bounds_;
    Vec3f cellSize_{1.0f}, inverseCellSize_{1.0f};
    int n_[3] = {0, 0, 0};
    size_t cells_ = 0;
    SegmentRefLayout layout_;
    size_t slots_ = 0;
    std::vector<std::vector<uint32_t>> lists_;    // per cell and bank
    size_t entries_ = 0, entriesAfterSweep_ = 0;  // in the cells, stale ones included
    // Per dynamic triangle hit by a tracked segment (and bank): rule (a).
    std::unordered_map<uint64_t, std::vector<uint32_t>> byTriangle_;
};

template <class ForEach>
void SegmentIndex::list(ForEach&& forEach) {
    const uint32_t shards = uint32_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    std::vector<size_t> listed(shards, 0);
    tbb::parallel_for(uint32_t(0), shards, [&](uint32_t shard) {
        forEach([&](const SegmentRef& ref, const uint32_t* cells, size_t cellCount) {
            const uint32_t bank = layout_.bankOf(ref.slot), entry = layout_.pack(ref);
            for (size_t c = 0; c < cellCount; ++c)
                if (cells[c] % shards == shard) {
                    pushBackModestly(cellList(cells[c], bank), entry);
                    ++listed[shard];
                }
        });
    });
    for (size_t n : listed) entries_ += n;
}

template <class IsLive, class Visit>
void SegmentIndex::visitNear(const std::vector<Bounds3f>& boxes, IsLive&& isLive, Visit&& visit) {
    const std::vector<uint8_t> marked = cellsOverlapping(boxes);
    // A segment is listed in every cell it passes: one bit per (slot, place) keeps it once,
    // without sorting what may be millions of entries; places past the 64 bits are sorted.
    std::vector<uint64_t> seen(slots_, 0);
    std::vector<SegmentRef> deep;
    for (size_t c = 0; c < cells_; ++c) {
        if (!marked[c]) continue;
        for (uint32_t bank = 0; bank < layout_.banks(); ++bank)
            entries_ -= filter(cellList(c, bank), bank, [&](const SegmentRef& r) {
                if (!isLive(r)) return false;
                if (r.place >= 64) {
                    deep.push_back(r);
                } else if (!(seen[r.slot] >> r.place & 1)) {
                    seen[r.slot] |= uint64_t(1) << r.place;
                    visit(r);
                }
                return true;
            });
    }
    auto samePlace = [](const SegmentRef& a, const SegmentRef& b) { return a.slot == b.slot && a.place == b.place; };
    std::sort(deep.begin(), deep.end(), [](const SegmentRef& a, const SegmentRef& b) {
        return a.slot < b.slot || (a.slot == b.slot && a.place < b.place);
    });
    deep.erase(std::unique(deep.begin(), deep.end(), samePlace), deep.end());
    for (const SegmentRef& r : deep) visit(r);
}

template <class IsLive, class Visit>
size_t SegmentIndex::visitListedOn(uint32_t triangle, IsLive&& isLive, Visit&& visit) {
    size_t read = 0;
    for (uint32_t bank = 0; bank < layout_.banks(); ++bank) {
        const auto list = byTriangle_.find(triangleKey(triangle, bank));
        if (list == byTriangle_.end()) continue;
        read += list->second.size();
        filter(list->second, bank, [&](const SegmentRef& r) {
            if (!isLive(r)) return false;
            visit(r);
            return true;
        });
    }
    return read;
}

template <class IsLive>
uint64_t SegmentIndex::countListedOn(const std::vector<uint32_t>& triangles, IsLive&& isLive) const {
    uint64_t n = 0;
    for (uint32_t t : triangles)
        for (uint32_t bank = 0; bank < layout_.banks(); ++bank)
            if (const auto list = byTriangle_.find(triangleKey(t, bank)); list != byTriangle_.end())
                for (uint32_t e : list->second) n += isLive(layout_.unpack(e, bank));
    return n;
}

template <class IsLive>
void SegmentIndex::sweep(IsLive&& isLive) {
    const uint32_t banks = layout_.banks();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, lists_.size(), 16), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i != range.end(); ++i) filter(lists_[i], uint32_t(i % banks), isLive);
    });
    for (auto& [key, list] : byTriangle_) filter(list, uint32_t(key % banks), isLive);
    entries_ = entriesAfterSweep_ = countEntries();
}

template <class IsLive>
void SegmentIndex::renumber(const SegmentRefLayout& layout, IsLive&& isLive) {
    const SegmentRefLayout old = layout_;
    const uint32_t oldBanks = old.banks(), banks = layout.banks();
    // Each cell's lists are rebuilt apart (a live entry may change banks): cells in parallel.
    std::vector<std::vector<uint32_t>> lists(cells_ * banks);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, cells_, 16), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t c = range.begin(); c != range.end(); ++c)
            for (uint32_t bank = 0; bank < oldBanks; ++bank) {
                std::vector<uint32_t>& from = lists_[c * oldBanks + bank];
                for (uint32_t e : from) {
                    SegmentRef r = old.unpack(e, bank);
                    if (!isLive(r)) continue;
                    r.generation = 0;
                    pushBackModestly(lists[c * banks + layout.bankOf(r.slot)], layout.pack(r));
                }
                std::vector<uint32_t>().swap(from);
            }
    });
    lists_.swap(lists);
    std::unordered_map<uint64_t, std::vector<uint32_t>> byTriangle;
    for (auto& [key, from] : byTriangle_) {
        const uint32_t triangle = uint32_t(key / oldBanks), bank = uint32_t(key % oldBanks);
        for (uint32_t e : from) {
            SegmentRef r = old.unpack(e, bank);
            if (!isLive(r)) continue;
            r.generation = 0;
            pushBackModestly(byTriangle[uint64_t(triangle) * banks + layout.bankOf(r.slot)], layout.pack(r));
        }
    }
    byTriangle_.swap(byTriangle);
    layout_ = layout;
    entries_ = entriesAfterSweep_ = countEntries();
}

}  // namespace qsgi
