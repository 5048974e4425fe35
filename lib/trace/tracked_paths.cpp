#include "trace/tracked_paths.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <limits>
#include <tuple>

#include "util/stopwatch.h"

namespace qsgi {

TrackedPaths::TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                           float cellSize)
    : envelope_(envelope), extension_(extension), grid_(gridBounds, cellSize) {
    const size_t n = cache.pathCount();
    // Per path, the first segment that meets the envelope (or none).
    std::vector<uint32_t> first(n, std::numeric_limits<uint32_t>::max());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t p = r.begin(); p != r.end(); ++p)
            for (uint64_t i = cache.pathBegin[p]; i < cache.pathBegin[p + 1]; ++i)
                if (envelope_.meets(cache.segments[i], extension_)) {
                    first[p] = uint32_t(i - cache.pathBegin[p]);
                    break;
                }
    });
    slot_.assign(n, -1);
    for (size_t p = 0; p < n; ++p) {
        if (first[p] == std::numeric_limits<uint32_t>::max()) continue;
        Tracked t;
        t.path = uint32_t(p);
        t.firstBounce = cache.segments[cache.pathBegin[p] + first[p]].bounce;
        t.begin = segments_.size();
        t.count = uint32_t(cache.pathBegin[p + 1] - cache.pathBegin[p] - first[p]);
        segments_.insert(segments_.end(), cache.segments.begin() + int64_t(cache.pathBegin[p] + first[p]),
                         cache.segments.begin() + int64_t(cache.pathBegin[p + 1]));
        slot_[p] = int32_t(paths_.size());
        paths_.push_back(t);
        liveSegments_ += t.count;
        index(t);
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
    grid_.insertInto(cells, cellCount, SegmentRef{t.path, t.generation, t.firstBounce + j});
    listOnTriangle(t, j);
}

void TrackedPaths::listOnTriangle(const Tracked& t, uint32_t j) {
    const Segment& s = segments_[t.begin + j];
    if (!s.hasImpact() || !s.impactDynamic) return;
    if (byTriangle_.size() <= s.triangle) byTriangle_.resize(size_t(s.triangle) + 1);
    byTriangle_[s.triangle].push_back(SegmentRef{t.path, t.generation, t.firstBounce + j});
}

bool TrackedPaths::isLive(const SegmentRef& r) const {
    const int32_t slot = slot_[r.path];
    return slot >= 0 && paths_[size_t(slot)].generation == r.generation;
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
                                                     bool useGrid, FrameTiming& stats) const {
    Stopwatch clock;
    constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
    // Per affected path (by slot), the first bounce to retrace from.
    std::vector<std::pair<uint32_t, uint32_t>> firstBounce;  // (slot, bounce)
    // (a) A segment that hit a triangle that moved: the photon would now land elsewhere.
    for (uint32_t tri : movedTriangles) {
        if (tri >= byTriangle_.size()) continue;
        stats.impactCandidates += byTriangle_[tri].size();
        for (const SegmentRef& r : byTriangle_[tri])
            if (isLive(r)) firstBounce.push_back({uint32_t(slot_[r.path]), r.bounce});
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
                        candidates.push_back(SegmentRef{t.path, t.generation, t.firstBounce + j});
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
    // New tails and the grid cells each new segment passes, found in parallel; fixed chunks of
    // paths, so nothing depends on the schedule.
    struct Chunk {
        std::vector<Segment> tails;
        std::vector<uint32_t> tailEnd;   // per path of the chunk: end of its tail in `tails`
        std::vector<uint32_t> cells;     // per segment of the new paths (kept head, then tail), its cells
        std::vector<uint32_t> cellsEnd;  // per such segment: end of its cells
    };
    constexpr size_t kChunk = 64;
    std::vector<Chunk> chunks((affected.size() + kChunk - 1) / kChunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, chunks.size()), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t c = r.begin(); c != r.end(); ++c) {
            Chunk& chunk = chunks[c];
            for (size_t i = c * kChunk; i < std::min(affected.size(), (c + 1) * kChunk); ++i) {
                const Tracked& t = paths_[size_t(slot_[affected[i].path])];
                const uint32_t keep = affected[i].bounce - t.firstBounce;
                const size_t tailBegin = chunk.tails.size();
                const Segment& s = segments_[t.begin + keep];
                tracer.continuePath(s.path, s.bounce, s.origin, s.direction, s.power, 0.0f, chunk.tails);
                chunk.tailEnd.push_back(uint32_t(chunk.tails.size()));
                auto list = [&](const Segment& x) {
                    grid_.cellsOf(x.origin, x.direction, reach(x), chunk.cells);
                    chunk.cellsEnd.push_back(uint32_t(chunk.cells.size()));
                };
                for (uint32_t j = 0; j < keep; ++j) list(segments_[t.begin + j]);
                for (size_t j = tailBegin; j < chunk.tails.size(); ++j) list(chunk.tails[j]);
            }
        }
    });
    // Sequential and in path order, so the cache's layout is the same for any thread count.
    size_t garbage = segments_.size() - liveSegments_;
    size_t removed = 0, added = 0, kept = 0;
    for (size_t i = 0; i < affected.size(); ++i) {
        const Tracked& t = paths_[size_t(slot_[affected[i].path])];
        kept += affected[i].bounce - t.firstBounce;
        removed += t.count - (affected[i].bounce - t.firstBounce);
    }
    for (const Chunk& c : chunks) added += c.tails.size();
    changes.removed.reserve(changes.removed.size() + removed);
    changes.added.reserve(changes.added.size() + added);
    const size_t needed = segments_.size() + added + kept;
    if (segments_.capacity() < needed) segments_.reserve(std::max(needed, segments_.capacity() + segments_.capacity() / 2));
    for (size_t i = 0; i < affected.size(); ++i) {
        const Chunk& chunk = chunks[i / kChunk];
        const size_t inChunk = i % kChunk;
        const uint32_t tailBegin = inChunk ? chunk.tailEnd[inChunk - 1] : 0, tailEnd = chunk.tailEnd[inChunk];
        Tracked& t = paths_[size_t(slot_[affected[i].path])];
        const uint32_t keep = affected[i].bounce - t.firstBounce;
        changes.removed.insert(changes.removed.end(), segments_.begin() + int64_t(t.begin + keep),
                               segments_.begin() + int64_t(t.begin + t.count));
        changes.added.insert(changes.added.end(), chunk.tails.begin() + tailBegin, chunk.tails.begin() + tailEnd);
        // The kept head is copied by index: segments_ has room reserved, so nothing moves.
        const uint64_t begin = segments_.size();
        for (uint32_t j = 0; j < keep; ++j) segments_.push_back(segments_[t.begin + j]);
        segments_.insert(segments_.end(), chunk.tails.begin() + tailBegin, chunk.tails.begin() + tailEnd);
        garbage += t.count;
        liveSegments_ = liveSegments_ + keep + (tailEnd - tailBegin) - t.count;
        t.begin = begin;
        t.count = keep + (tailEnd - tailBegin);
        ++t.generation;
        // Listed on its dynamic triangles under the new generation (the grid follows below).
        for (uint32_t j = 0; j < t.count; ++j) listOnTriangle(t, j);
    }
    // The grid's cells, filled in parallel by shards of cells: each cell takes its entries in
    // path order, whatever the thread count.
    const uint32_t kShards = uint32_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    tbb::parallel_for(uint32_t(0), kShards, [&](uint32_t shard) {
        for (size_t c = 0; c < chunks.size(); ++c) {
            const Chunk& chunk = chunks[c];
            size_t n = 0;  // segments of the chunk whose cells were listed
            for (size_t i = c * kChunk; i < std::min(affected.size(), (c + 1) * kChunk); ++i) {
                const Tracked& t = paths_[size_t(slot_[affected[i].path])];
                for (uint32_t j = 0; j < t.count; ++j, ++n) {
                    const uint32_t from = n ? chunk.cellsEnd[n - 1] : 0;
                    grid_.insertIntoShard(chunk.cells.data() + from, chunk.cellsEnd[n] - from,
                                                           SegmentRef{t.path, t.generation, t.firstBounce + j}, shard, kShards);
                }
            }
        }
    });
    stats.pathsRetraced += affected.size();
    stats.segmentsRemoved += removed;
    stats.segmentsAdded += added;
    // Retraced paths leave their old segments behind; compact once they are half the store.
    if (garbage > liveSegments_) {
        std::vector<Segment> compact;
        compact.reserve(liveSegments_);
        for (Tracked& t : paths_) {
            const uint64_t begin = compact.size();
            compact.insert(compact.end(), segments_.begin() + int64_t(t.begin), segments_.begin() + int64_t(t.begin + t.count));
            t.begin = begin;
        }
        segments_.swap(compact);
        auto live = [&](const SegmentRef& r) { return isLive(r); };
        grid_.sweep(live);
        for (auto& list : byTriangle_)
            list.erase(std::remove_if(list.begin(), list.end(), [&](const SegmentRef& r) { return !live(r); }), list.end());
    }
    stats.retraceSeconds += clock.seconds();
}

void TrackedPaths::refsNear(const std::vector<Bounds3f>& boxes, std::vector<SegmentRef>& out) const {
    out.clear();
    // A segment is listed in every cell it passes: one bit per (path, bounce) keeps it once,
    // without sorting what may be millions of entries.
    std::vector<uint64_t> seen(paths_.size(), 0);
    std::vector<SegmentRef> deep;  // bounces past the 64 bits, deduplicated by sorting
    grid_.visitCells(boxes, [&](const SegmentRef& r) {
        const int32_t slot = slot_[r.path];
        if (slot < 0) return;
        const Tracked& t = paths_[size_t(slot)];
        if (t.generation != r.generation) return;
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
    return segments_.capacity() * sizeof(Segment) + paths_.capacity() * sizeof(Tracked) + slot_.capacity() * sizeof(int32_t) +
           grid_.bytes() + listed;
}

}  // namespace qsgi
