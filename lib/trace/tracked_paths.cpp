#include "trace/tracked_paths.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <tuple>

#include "util/modest_growth.h"
#include "util/stopwatch.h"

namespace qsgi {

TrackedPaths::TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                           float cellSize, uint32_t generations)
    : envelope_(envelope), extension_(extension), generations_(std::clamp<uint32_t>(generations, 2, kGenerations)),
      grid_(gridBounds, cellSize) {
    const size_t n = cache.pathCount();
    // Per block of paths, the tails from the first segment that meets the envelope on, found in
    // parallel and then taken in path order.
    struct Tail {
        uint32_t path, firstBounce, count;
    };
    std::vector<std::vector<Tail>> tails(cache.blockCount());
    std::vector<std::vector<Segment>> kept(cache.blockCount());
    cache.forEachBlock([&](size_t b, const std::vector<Segment>& block) {
        for (size_t i = 0; i < block.size();) {
            size_t end = i + 1;
            while (end < block.size() && block[end].path == block[i].path) ++end;
            for (size_t j = i; j < end; ++j)
                if (envelope_.meets(block[j], extension_)) {
                    tails[b].push_back({block[i].path, block[j].bounce, uint32_t(end - j)});
                    kept[b].insert(kept[b].end(), block.begin() + int64_t(j), block.begin() + int64_t(end));
                    break;
                }
            i = end;
        }
    });
    slot_.assign(n, -1);
    retracedSinceSweep_.assign((n + 63) / 64, 0);
    // Exactly the room needed: the store is most of the tracked state.
    size_t pathCount = 0, segmentCount = 0;
    for (size_t b = 0; b < tails.size(); ++b) {
        pathCount += tails[b].size();
        segmentCount += kept[b].size();
    }
    paths_.reserve(pathCount);
    segments_.reserve(segmentCount);
    generation_.reserve(segmentCount);
    cellCount_.reserve(segmentCount);
    for (size_t b = 0; b < tails.size(); ++b) {
        size_t from = 0;
        for (const Tail& tail : tails[b]) {
            Tracked t;
            t.path = tail.path;
            t.firstBounce = uint16_t(tail.firstBounce);
            t.begin = segments_.size();
            t.count = t.capacity = tail.count;
            segments_.insert(segments_.end(), kept[b].begin() + int64_t(from), kept[b].begin() + int64_t(from + tail.count));
            from += tail.count;
            generation_.resize(segments_.size(), 0);
            cellCount_.resize(segments_.size(), 0);
            slot_[t.path] = int32_t(paths_.size());
            paths_.push_back(t);
            liveSegments_ += t.count;
            index(t);
        }
        std::vector<Segment>().swap(kept[b]);
    }
}

double TrackedPaths::reach(const Segment& s) const {
    return s.hasImpact() ? double(s.length) + double(extension_) : std::numeric_limits<double>::infinity();
}

void TrackedPaths::index(const Tracked& t) {
    std::vector<uint32_t> cells;
    for (uint32_t j = 0; j < t.count; ++j) {
        const Segment& s = segments_[t.begin + j];
        cells.clear();
        grid_.cellsOf(s.origin, s.direction, reach(s), cells);
        indexSegment(t, j, cells.data(), cells.size());
    }
}

void TrackedPaths::indexSegment(const Tracked& t, uint32_t j, const uint32_t* cells, size_t cellCount) {
    grid_.insertInto(cells, cellCount, refOf(t, j));
    cellCount_[t.begin + j] = uint16_t(cellCount);
    gridEntries_ += cellCount;
    liveGridEntries_ += cellCount;
    listOnTriangle(t, j);
}

void TrackedPaths::listOnTriangle(const Tracked& t, uint32_t j) {
    const Segment& s = segments_[t.begin + j];
    if (!s.hasImpact() || !s.impactDynamic) return;
    if (byTriangle_.size() <= s.triangle) byTriangle_.resize(size_t(s.triangle) + 1);
    pushBackModestly(byTriangle_[s.triangle], refOf(t, j));
}

bool TrackedPaths::isLive(const SegmentRef& r) const {
    const int32_t slot = slot_[r.path];
    if (slot < 0) return false;
    const Tracked& t = paths_[size_t(slot)];
    const uint32_t j = r.bounce - t.firstBounce;  // wraps for bounces before the first: not live
    return j < t.count && generation_[t.begin + j] == r.generation;
}

const Segment* TrackedPaths::segmentOf(const SegmentRef& r) const {
    const Tracked& t = paths_[size_t(slot_[r.path])];
    return &segments_[t.begin + (r.bounce - t.firstBounce)];
}

uint64_t TrackedPaths::segmentsListedOn(const std::vector<uint32_t>& triangles) const {
    uint64_t n = 0;
    for (uint32_t t : triangles)
        if (t < byTriangle_.size())
            for (const SegmentRef& r : byTriangle_[t]) n += isLive(r);
    return n;
}

std::vector<AffectedPath> TrackedPaths::findAffected(const std::vector<uint32_t>& movedTriangles,
                                                     const std::vector<uint8_t>& triangleMoved,
                                                     const std::vector<Bounds3f>& newBounds, const SceneBvh& bvh,
                                                     bool useGrid, FrameTiming& stats) {
    Stopwatch clock;
    constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
    // Per affected path (by slot), the first bounce to retrace from.
    std::vector<std::pair<uint32_t, uint32_t>> firstBounce;  // (slot, bounce)
    // (a) A segment that hit a triangle that moved: the photon would now land elsewhere.
    for (uint32_t tri : movedTriangles) {
        if (tri >= byTriangle_.size()) continue;
        std::vector<SegmentRef>& list = byTriangle_[tri];
        stats.impactCandidates += list.size();
        // Stale entries are dropped on the way (the order of the rest is kept).
        size_t kept = 0;
        for (const SegmentRef& r : list) {
            if (!isLive(r)) continue;
            list[kept++] = r;
            firstBounce.push_back({uint32_t(slot_[r.path]), r.bounce});
        }
        list.resize(kept);
    }
    auto firstPerPath = [](std::vector<std::pair<uint32_t, uint32_t>>& list) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
                   list.end());
    };
    firstPerPath(firstBounce);
    stats.pathsAffectedByImpact += firstBounce.size();

    // (b) A segment that a moved triangle now blocks before its impact. Only segments passing
    // through a moved object's new bounds can be; the grid lists them, the dynamic BVH decides,
    // counting moved triangles only (a deforming mesh's unmoved part blocks nothing new).
    // The test reaches a little past the impact: a tie there is the tracer's to decide, and
    // retracing a path that would not change repeats the full trace exactly.
    const float eps = bvh.rayEpsilon();
    auto blocked = [&](const Segment& s) {
        const float end = s.hasImpact() ? s.length + eps : s.length;
        // The grid lists whole cells: most candidates pass beside the moved bounds themselves.
        bool near = false;
        for (const Bounds3f& b : newBounds) {
            double t0 = 0, t1 = double(end);
            near = near || b.expanded(eps).clip(s.origin, s.direction, t0, t1);
        }
        return near && bvh.movedOccludes(s.origin, s.direction, 0.0f, end, triangleMoved);
    };
    std::vector<SegmentRef> candidates;
    if (useGrid) {
        std::vector<Bounds3f> boxes;
        for (const Bounds3f& b : newBounds) boxes.push_back(b.expanded(eps));
        refsNear(boxes, candidates);
    } else {
        for (const Tracked& t : paths_)
            for (uint32_t j = 0; j < t.count; ++j) {
                const Segment& s = segments_[t.begin + j];
                for (const Bounds3f& b : newBounds) {
                    double t0 = 0, t1 = double(s.length) + double(eps);
                    if (b.expanded(eps).clip(s.origin, s.direction, t0, t1)) {
                        candidates.push_back(refOf(t, j));
                        break;
                    }
                }
            }
    }
    stats.blockingCandidates += candidates.size();
    // A path that rule (a) retraces from this bounce or earlier changes the same way whether
    // or not the candidate is blocked: no need to ask.
    std::vector<uint32_t> fromImpact(paths_.size(), kNone);
    for (const auto& [slot, bounce] : firstBounce) fromImpact[slot] = bounce;
    std::vector<uint8_t> isBlocked(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i)
            isBlocked[i] = fromImpact[size_t(slot_[candidates[i].path])] > candidates[i].bounce && blocked(*segmentOf(candidates[i]));
    });
    std::vector<std::pair<uint32_t, uint32_t>> byBlocking;
    for (size_t i = 0; i < candidates.size(); ++i)
        if (isBlocked[i]) byBlocking.push_back({uint32_t(slot_[candidates[i].path]), candidates[i].bounce});
    firstPerPath(byBlocking);

    // Merge: per path the earlier of the two bounces; paths in increasing id (slots are).
    std::vector<AffectedPath> affected;
    affected.reserve(firstBounce.size() + byBlocking.size());
    size_t i = 0, j = 0;
    while (i < firstBounce.size() || j < byBlocking.size()) {
        uint32_t slot, bounce = kNone;
        if (j == byBlocking.size() || (i < firstBounce.size() && firstBounce[i].first < byBlocking[j].first)) {
            std::tie(slot, bounce) = firstBounce[i++];
        } else if (i == firstBounce.size() || byBlocking[j].first < firstBounce[i].first) {
            std::tie(slot, bounce) = byBlocking[j++];
            ++stats.pathsAffectedByBlocking;
        } else {
            slot = firstBounce[i].first;
            bounce = std::min(firstBounce[i++].second, byBlocking[j++].second);
        }
        affected.push_back({paths_[slot].path, bounce});
    }
    stats.findAffectedSeconds += clock.seconds();
    return affected;
}

void TrackedPaths::retrace(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer, PathChanges& changes,
                           FrameTiming& stats) {
    Stopwatch clock;
    for (const AffectedPath& a : affected)
        if (paths_[size_t(slot_[a.path])].generation + 1u >= generations_) {
            renumber();
            break;
        }
    for (const AffectedPath& a : affected) retracedSinceSweep_[a.path >> 6] |= uint64_t(1) << (a.path & 63);
    // New tails and the grid cells each new segment passes, found in parallel; fixed chunks of
    // paths, so nothing depends on the schedule. The kept heads stay listed as they are.
    struct Chunk {
        std::vector<Segment> tails;
        std::vector<uint32_t> tailEnd;   // per path of the chunk: end of its tail in `tails`
        std::vector<uint32_t> cells;     // per new segment, its cells
        std::vector<uint32_t> cellsEnd;  // per new segment: end of its cells
    };
    constexpr size_t kChunk = 64;
    std::vector<Chunk> chunks((affected.size() + kChunk - 1) / kChunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            Chunk& chunk = chunks[c];
            for (size_t i = c * kChunk; i < std::min(affected.size(), (c + 1) * kChunk); ++i) {
                const Tracked& t = paths_[size_t(slot_[affected[i].path])];
                const Segment& s = segments_[t.begin + (affected[i].bounce - t.firstBounce)];
                const size_t tailBegin = chunk.tails.size();
                tracer.continuePath(s.path, s.bounce, s.origin, s.direction, s.power, 0.0f, chunk.tails);
                chunk.tailEnd.push_back(uint32_t(chunk.tails.size()));
                for (size_t j = tailBegin; j < chunk.tails.size(); ++j) {
                    const Segment& x = chunk.tails[j];
                    grid_.cellsOf(x.origin, x.direction, reach(x), chunk.cells);
                    chunk.cellsEnd.push_back(uint32_t(chunk.cells.size()));
                }
            }
        }
    });
    auto tailOf = [&](size_t i, uint32_t& begin, uint32_t& end) {
        const Chunk& chunk = chunks[i / kChunk];
        const size_t inChunk = i % kChunk;
        begin = inChunk ? chunk.tailEnd[inChunk - 1] : 0;
        end = chunk.tailEnd[inChunk];
    };

    // Where everything goes, in path order (so the store's layout is the same for any thread
    // count): offsets into the removed and added lists, and a new place for a path whose tail
    // no longer fits its room.
    struct Move {
        uint64_t removedAt, addedAt;
        uint64_t begin;  // the path's place after the retrace
        uint32_t keep, tailBegin, tailEnd, capacity;
        uint64_t cellsAt;  // the chunk's cells of this path's first new segment
    };
    std::vector<Move> moves(affected.size());
    uint64_t removed = 0, added = 0, end = segments_.size();
    size_t staleEntries = 0;
    for (size_t i = 0; i < affected.size(); ++i) {
        const Tracked& t = paths_[size_t(slot_[affected[i].path])];
        Move& m = moves[i];
        m.keep = affected[i].bounce - t.firstBounce;
        tailOf(i, m.tailBegin, m.tailEnd);
        m.removedAt = removed;
        m.addedAt = added;
        removed += t.count - m.keep;
        added += m.tailEnd - m.tailBegin;
        for (uint32_t j = m.keep; j < t.count; ++j) staleEntries += cellCount_[t.begin + j];
        const uint32_t count = m.keep + (m.tailEnd - m.tailBegin);
        m.begin = t.begin;
        m.capacity = t.capacity;
        if (count > t.capacity) {
            // Room to grow by a few bounces, so that the next retraces fit where they land.
            m.capacity = (count + 4) & ~3u;
            m.begin = end;
            end += m.capacity;
            garbage_ += t.capacity;
        }
    }
    // The first new segment's cells of each path: where the previous path's new segments end.
    for (size_t c = 0; c < chunks.size(); ++c) {
        size_t segment = 0;
        for (size_t i = c * kChunk; i < std::min(affected.size(), (c + 1) * kChunk); ++i) {
            moves[i].cellsAt = segment;
            segment += moves[i].tailEnd - moves[i].tailBegin;
        }
    }
    if (segments_.capacity() < end) {
        const size_t room = std::max<size_t>(end, segments_.capacity() + segments_.capacity() / 4);
        segments_.reserve(room);
        generation_.reserve(room);
        cellCount_.reserve(room);
    }
    segments_.resize(end);
    generation_.resize(end, 0);
    cellCount_.resize(end, 0);
    const size_t removedBefore = changes.removed.size(), addedBefore = changes.added.size();
    changes.removed.resize(removedBefore + removed);
    changes.added.resize(addedBefore + added);

    // Each path writes only its own places: in parallel.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, affected.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const Tracked& t = paths_[size_t(slot_[affected[i].path])];
            const Move& m = moves[i];
            const Chunk& chunk = chunks[i / kChunk];
            std::copy(segments_.begin() + int64_t(t.begin + m.keep), segments_.begin() + int64_t(t.begin + t.count),
                      changes.removed.begin() + int64_t(removedBefore + m.removedAt));
            std::copy(chunk.tails.begin() + m.tailBegin, chunk.tails.begin() + m.tailEnd,
                      changes.added.begin() + int64_t(addedBefore + m.addedAt));
            if (m.begin != t.begin) {
                std::copy_n(segments_.begin() + int64_t(t.begin), m.keep, segments_.begin() + int64_t(m.begin));
                std::copy_n(generation_.begin() + int64_t(t.begin), m.keep, generation_.begin() + int64_t(m.begin));
                std::copy_n(cellCount_.begin() + int64_t(t.begin), m.keep, cellCount_.begin() + int64_t(m.begin));
            }
            std::copy(chunk.tails.begin() + m.tailBegin, chunk.tails.begin() + m.tailEnd,
                      segments_.begin() + int64_t(m.begin + m.keep));
            for (uint32_t j = 0; j < m.tailEnd - m.tailBegin; ++j) {
                const size_t n = m.cellsAt + j;
                const uint32_t from = n ? chunk.cellsEnd[n - 1] : 0;
                generation_[m.begin + m.keep + j] = uint16_t(t.generation + 1);
                cellCount_[m.begin + m.keep + j] = uint16_t(chunk.cellsEnd[n] - from);
            }
        }
    });
    // The paths' records, and the new segments on dynamic triangles listed in path order.
    size_t newEntries = 0;
    for (const Chunk& c : chunks) newEntries += c.cells.size();
    for (size_t i = 0; i < affected.size(); ++i) {
        Tracked& t = paths_[size_t(slot_[affected[i].path])];
        const Move& m = moves[i];
        const uint32_t count = m.keep + (m.tailEnd - m.tailBegin);
        liveSegments_ = liveSegments_ + count - t.count;
        t.begin = m.begin;
        t.count = count;
        t.capacity = m.capacity;
        ++t.generation;
        for (uint32_t j = m.keep; j < t.count; ++j) listOnTriangle(t, j);
    }
    // The grid's cells, filled in parallel by shards of cells: each cell takes its entries in
    // path order, whatever the thread count.
    const uint32_t kShards = uint32_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    tbb::parallel_for(uint32_t(0), kShards, [&](uint32_t shard) {
        for (size_t c = 0; c < chunks.size(); ++c) {
            const Chunk& chunk = chunks[c];
            for (size_t i = c * kChunk; i < std::min(affected.size(), (c + 1) * kChunk); ++i) {
                const Tracked& t = paths_[size_t(slot_[affected[i].path])];
                const Move& m = moves[i];
                for (uint32_t j = 0; j < m.tailEnd - m.tailBegin; ++j) {
                    const size_t n = m.cellsAt + j;
                    const uint32_t from = n ? chunk.cellsEnd[n - 1] : 0;
                    grid_.insertIntoShard(chunk.cells.data() + from, chunk.cellsEnd[n] - from,
                                          refOf(t, m.keep + j), shard, kShards);
                }
            }
        }
    });
    gridEntries_ += newEntries;
    liveGridEntries_ = liveGridEntries_ + newEntries - staleEntries;
    stats.pathsRetraced += affected.size();
    stats.segmentsRemoved += removed;
    stats.segmentsAdded += added;
    sweepIfStale();
    stats.retraceSeconds += clock.seconds();
}

void TrackedPaths::sweepIfStale() {
    auto live = [&](const SegmentRef& r) { return isLive(r); };
    // At half the live ones stale, a sweep runs every fifth frame or so on data/cornell. Only
    // entries of paths retraced since the last sweep can be stale: the rest are kept on a look
    // at a bitmap that stays in cache, not at three scattered records.
    if (2 * gridEntries_ > 3 * liveGridEntries_) {
        grid_.sweep([&](const SegmentRef& r) { return !(retracedSinceSweep_[r.path >> 6] >> (r.path & 63) & 1) || isLive(r); });
        std::fill(retracedSinceSweep_.begin(), retracedSinceSweep_.end(), uint64_t(0));
        for (auto& list : byTriangle_)
            list.erase(std::remove_if(list.begin(), list.end(), [&](const SegmentRef& r) { return !live(r); }), list.end());
        gridEntries_ = liveGridEntries_;
    }
    if (4 * garbage_ > segments_.size() - garbage_) {
        // In place, taking the paths in the order they sit in the store: each moves down or
        // stays, so nothing is overwritten before it has moved, and no second store is needed.
        // References name (path, generation, bounce), not places: moving paths keeps them.
        std::vector<uint32_t> byPlace(paths_.size());
        std::iota(byPlace.begin(), byPlace.end(), 0u);
        std::sort(byPlace.begin(), byPlace.end(), [&](uint32_t a, uint32_t b) { return paths_[a].begin < paths_[b].begin; });
        uint64_t end = 0;
        for (uint32_t i : byPlace) {
            Tracked& t = paths_[i];
            if (t.begin != end) {
                const auto from = int64_t(t.begin), to = int64_t(end), count = int64_t(t.count);
                std::copy(segments_.begin() + from, segments_.begin() + from + count, segments_.begin() + to);
                std::copy(generation_.begin() + from, generation_.begin() + from + count, generation_.begin() + to);
                std::copy(cellCount_.begin() + from, cellCount_.begin() + from + count, cellCount_.begin() + to);
                t.begin = end;
            }
            // Each path keeps its room (the store grows by retraces that outgrow it only).
            end += t.capacity;
        }
        segments_.resize(end);
        generation_.resize(end);
        cellCount_.resize(end);
        garbage_ = 0;
    }
}

void TrackedPaths::renumber() {
    ++renumberings_;
    grid_.clear();
    for (auto& list : byTriangle_) std::vector<SegmentRef>().swap(list);
    gridEntries_ = liveGridEntries_ = 0;
    std::fill(generation_.begin(), generation_.end(), uint16_t(0));
    for (Tracked& t : paths_) {
        t.generation = 0;
        index(t);
    }
}

void TrackedPaths::refsNear(const std::vector<Bounds3f>& boxes, std::vector<SegmentRef>& out) const {
    out.clear();
    // A segment is listed in every cell it passes: one bit per (path, bounce) keeps it once,
    // without sorting what may be millions of entries.
    std::vector<uint64_t> seen(paths_.size(), 0);
    std::vector<SegmentRef> deep;  // bounces past the 64 bits, deduplicated by sorting
    gridEntries_ -= grid_.visitLiveCells(boxes, [&](const SegmentRef& r) { return isLive(r); }, [&](const SegmentRef& r) {
        const int32_t slot = slot_[r.path];
        const Tracked& t = paths_[size_t(slot)];
        const uint32_t bit = r.bounce - t.firstBounce;
        if (bit >= 64) {
            deep.push_back(r);
            return;
        }
        uint64_t& mask = seen[size_t(slot)];
        if (mask >> bit & 1) return;
        mask |= uint64_t(1) << bit;
        out.push_back(r);
    });
    std::sort(deep.begin(), deep.end());
    deep.erase(std::unique(deep.begin(), deep.end()), deep.end());
    out.insert(out.end(), deep.begin(), deep.end());
}

void TrackedPaths::allSegments(std::vector<const Segment*>& out) const {
    for (const Tracked& t : paths_)
        for (uint32_t j = 0; j < t.count; ++j) out.push_back(&segments_[t.begin + j]);
}

size_t TrackedPaths::bytes() const {
    size_t listed = byTriangle_.capacity() * sizeof(byTriangle_[0]);
    for (const auto& list : byTriangle_) listed += list.capacity() * sizeof(SegmentRef);
    return segments_.capacity() * sizeof(Segment) + generation_.capacity() * sizeof(uint16_t) +
           cellCount_.capacity() * sizeof(uint16_t) + paths_.capacity() * sizeof(Tracked) +
           slot_.capacity() * sizeof(int32_t) + retracedSinceSweep_.capacity() * sizeof(uint64_t) + grid_.bytes() + listed;
}

}  // namespace qsgi
