#include "trace/tracked_paths.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

#include "util/stopwatch.h"

namespace qsgi {

TrackedPaths::TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                           float cellSize, std::vector<Segment>* untracked)
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
        const uint64_t kept = first[p] == std::numeric_limits<uint32_t>::max() ? cache.pathBegin[p + 1] : cache.pathBegin[p] + first[p];
        if (untracked)
            untracked->insert(untracked->end(), cache.segments.begin() + int64_t(cache.pathBegin[p]), cache.segments.begin() + int64_t(kept));
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
    for (uint32_t j = 0; j < t.count; ++j) {
        const Segment& s = segments_[t.begin + j];
        grid_.insert(s.origin, s.direction, reach(s), SegmentRef{t.path, t.generation, t.firstBounce + j});
    }
}

bool TrackedPaths::isLive(const SegmentRef& r) const {
    const int32_t slot = slot_[r.path];
    return slot >= 0 && paths_[size_t(slot)].generation == r.generation;
}

const Segment* TrackedPaths::segmentOf(const SegmentRef& r) const {
    const Tracked& t = paths_[size_t(slot_[r.path])];
    return &segments_[t.begin + (r.bounce - t.firstBounce)];
}

std::vector<AffectedPath> TrackedPaths::findAffected(const std::vector<uint8_t>& triangleMoved,
                                                     const std::vector<Bounds3f>& newBounds, const SceneBvh& bvh,
                                                     bool useGrid, PathChanges& changes) const {
    Stopwatch clock;
    constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
    std::vector<uint32_t> from(paths_.size(), kNone);
    // (a) A segment that hit a triangle that moved: the photon would now land elsewhere.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, paths_.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const Tracked& t = paths_[i];
            for (uint32_t j = 0; j < t.count; ++j) {
                const Segment& s = segments_[t.begin + j];
                if (s.hasImpact() && s.impactDynamic && triangleMoved[s.triangle]) {
                    from[i] = t.firstBounce + j;
                    break;
                }
            }
        }
    });
    for (uint32_t f : from) changes.affectedByImpact += f != kNone;

    // (b) A segment that a moved triangle now blocks before its impact. Only segments passing
    // through a moved object's new bounds can be; the grid lists them, the dynamic BVH decides,
    // counting moved triangles only (a deforming mesh's unmoved part blocks nothing new).
    // The test reaches a little past the impact: a tie there is the tracer's to decide, and
    // retracing a path that would not change repeats the full trace exactly.
    const float eps = bvh.rayEpsilon();
    auto blocked = [&](const Segment& s) {
        const float end = s.hasImpact() ? s.length + eps : s.length;
        return bvh.movedOccludes(s.origin, s.direction, 0.0f, end, triangleMoved);
    };
    std::vector<SegmentRef> candidates;
    if (useGrid) {
        std::vector<SegmentRef> near;
        for (const Bounds3f& b : newBounds) {
            grid_.query(b.expanded(eps), near, [&](const SegmentRef& r) { return isLive(r); });
            candidates.insert(candidates.end(), near.begin(), near.end());
        }
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
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
    changes.blockingCandidates += candidates.size();
    std::vector<uint8_t> isBlocked(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) isBlocked[i] = blocked(*segmentOf(candidates[i]));
    });
    for (size_t i = 0; i < candidates.size(); ++i) {
        if (!isBlocked[i]) continue;
        uint32_t& f = from[size_t(slot_[candidates[i].path])];
        if (f == kNone) ++changes.affectedByBlocking;
        f = std::min(f, candidates[i].bounce);
    }

    std::vector<AffectedPath> affected;
    for (size_t i = 0; i < paths_.size(); ++i)
        if (from[i] != kNone) affected.push_back({paths_[i].path, from[i]});
    changes.findSeconds += clock.seconds();
    return affected;
}

void TrackedPaths::retrace(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer, PathChanges& changes) {
    Stopwatch clock;
    std::vector<std::vector<Segment>> tails(affected.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, affected.size(), 16), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const Tracked& t = paths_[size_t(slot_[affected[i].path])];
            const Segment& s = segments_[t.begin + (affected[i].bounce - t.firstBounce)];
            tracer.continuePath(s.path, s.bounce, s.origin, s.direction, s.power, 0.0f, tails[i]);
        }
    });
    // Sequential and in path order, so the cache's layout is the same for any thread count.
    size_t garbage = segments_.size() - liveSegments_;
    for (size_t i = 0; i < affected.size(); ++i) {
        Tracked& t = paths_[size_t(slot_[affected[i].path])];
        const uint32_t keep = affected[i].bounce - t.firstBounce;
        changes.removed.insert(changes.removed.end(), segments_.begin() + int64_t(t.begin + keep),
                               segments_.begin() + int64_t(t.begin + t.count));
        changes.added.insert(changes.added.end(), tails[i].begin(), tails[i].end());
        // The kept head goes through a copy: inserting a vector's own range into it is undefined.
        const std::vector<Segment> head(segments_.begin() + int64_t(t.begin), segments_.begin() + int64_t(t.begin + keep));
        const uint64_t begin = segments_.size();
        segments_.insert(segments_.end(), head.begin(), head.end());
        segments_.insert(segments_.end(), tails[i].begin(), tails[i].end());
        garbage += t.count;
        liveSegments_ += keep + tails[i].size() - t.count;
        t.begin = begin;
        t.count = uint32_t(keep + tails[i].size());
        ++t.generation;
        index(t);
    }
    changes.pathsRetraced += affected.size();
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
        grid_.sweep([&](const SegmentRef& r) { return isLive(r); });
    }
    changes.retraceSeconds += clock.seconds();
}

void TrackedPaths::segmentsNear(const Bounds3f& box, std::vector<const Segment*>& out) const {
    std::vector<SegmentRef> refs;
    grid_.query(box, refs, [&](const SegmentRef& r) { return isLive(r); });
    for (const SegmentRef& r : refs) out.push_back(segmentOf(r));
}

void TrackedPaths::appendAll(std::vector<Segment>& out) const {
    for (const Tracked& t : paths_)
        out.insert(out.end(), segments_.begin() + int64_t(t.begin), segments_.begin() + int64_t(t.begin + t.count));
}

void TrackedPaths::allSegments(std::vector<const Segment*>& out) const {
    for (const Tracked& t : paths_)
        for (uint32_t j = 0; j < t.count; ++j) out.push_back(&segments_[t.begin + j]);
}

size_t TrackedPaths::bytes() const {
    return segments_.capacity() * sizeof(Segment) + paths_.capacity() * sizeof(Tracked) + slot_.capacity() * sizeof(int32_t) +
           grid_.bytes();
}

}  // namespace qsgi
