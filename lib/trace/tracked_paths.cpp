#include "trace/tracked_paths.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <tuple>

#include "trace/path_groups.h"
#include "trace/photon_source.h"
#include "util/stopwatch.h"

namespace qsgi {

namespace {

// Segments and the grid cells each passes, found in parallel for a fixed run of paths: per path
// the end of its segments, per segment the end of its cells.
struct CellsOfRun {
    std::vector<Segment> segments;  // a retrace's new tails (none when indexing the store's own records)
    std::vector<uint32_t> segmentsEnd;
    std::vector<uint32_t> cells;
    std::vector<uint32_t> cellsEnd;

    uint32_t segmentsBegin(size_t i) const { return i ? segmentsEnd[i - 1] : 0; }
    uint32_t cellsBegin(size_t n) const { return n ? cellsEnd[n - 1] : 0; }
};

// Fixed chunks of paths, so that nothing depends on the schedule.
constexpr size_t kChunk = 64;

}  // namespace

TrackedPaths::TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                           float cellSize, uint32_t generations)
    : source_(cache.source()), extension_(extension), generations_(generations) {
    if (!source_) throw std::logic_error("TrackedPaths: the cache has no photon source to decode with");
    // Per block of paths, the tails from the first segment that meets the envelope on, found in
    // parallel and then taken in path order.
    std::vector<std::vector<Segment>> kept(cache.blockCount());
    cache.forEachBlock([&](size_t b, const std::vector<Segment>& block) {
        forEachPathGroup(block, [&](size_t begin, size_t end) {
            envelope.appendTail(block.data() + begin, block.data() + end, extension_, kept[b]);
        });
    });
    keep(kept, gridBounds, cellSize);
}

TrackedPaths::TrackedPaths(std::shared_ptr<const PhotonSource> source, EnvelopeTails& tails, const Bounds3f& gridBounds,
                           float cellSize, uint32_t generations)
    : source_(std::move(source)), extension_(tails.extension), generations_(generations) {
    if (!source_) throw std::logic_error("TrackedPaths: no photon source to decode with");
    keep(tails.blocks, gridBounds, cellSize);
}

void TrackedPaths::keep(std::vector<std::vector<Segment>>& kept, const Bounds3f& gridBounds, float cellSize) {
    size_t slots = 0, segments = 0;
    uint32_t longest = 0;
    for (const std::vector<Segment>& tails : kept) {
        forEachPathGroup(tails, [&](size_t begin, size_t end) {
            ++slots;
            longest = std::max(longest, uint32_t(end - begin));
        });
        segments += tails.size();
    }
    const SegmentRefLayout layout(slots, longest);
    store_ = SlottedPathStore<Record, HitPoint>(slots, {true, source_->anyVaries()}, std::min(generations_, layout.generations()));
    // Exactly the room needed: the store is most of the tracked state.
    store_.reserve(segments);
    pathOf_.reserve(slots);
    firstBounce_.reserve(slots);
    power_.reserve(slots);
    for (std::vector<Segment>& tails : kept) {
        forEachPathGroup(tails, [&](size_t begin, size_t end) {
            const uint32_t s = uint32_t(pathOf_.size());
            pathOf_.push_back(tails[begin].path);
            firstBounce_.push_back(tails[begin].bounce);
            if (source_->anyTransmits()) firstScattered_.push_back(tails[begin].scattered);
            power_.push_back(tails[begin].power);
            store_.append(s, uint32_t(end - begin));
            writeRecords(s, 0, tails.data() + begin, uint32_t(end - begin));
        });
        std::vector<Segment>().swap(tails);
    }
    retracedSinceSweep_.assign((slots + 63) / 64, 0);
    index_ = SegmentIndex(gridBounds, cellSize, layout, slots);
    indexSlots(0, uint32_t(slots));
    index_.allLive();
}

double TrackedPaths::reach(const Record& r) const {
    return r.triangle != kNoTriangle ? double(r.length) + double(extension_) : std::numeric_limits<double>::infinity();
}

void TrackedPaths::writeRecords(uint32_t s, uint32_t at, const Segment* from, uint32_t count) {
    if (count == 0) return;
    Record* records = &store_.at<0>(s, at);
    for (uint32_t j = 0; j < count; ++j) records[j] = recordOf(from[j]);
    if (!source_->anyVaries()) return;
    HitPoint* hits = &store_.at<1>(s, at);
    for (uint32_t j = 0; j < count; ++j) hits[j] = {from[j].b1, from[j].b2};
}

void TrackedPaths::decode(uint32_t s, uint32_t from, uint32_t to, Segment* out) const {
    const Record* records = store_.column<0>() + store_.slot(s).begin;
    const HitPoint* hits = source_->anyVaries() ? store_.column<1>() + store_.slot(s).begin : nullptr;
    Vec3f power = power_[s];
    bool scattered = firstScatteredAt(s);
    // What each impact did (PhotonSource::impact) where some surface lets photons through.
    const bool transmits = source_->anyTransmits();
    const PathNumbers numbers = transmits ? source_->numbersFor(pathOf_[s]) : PathNumbers(0, 0);
    for (uint32_t j = 0; j < to; ++j) {
        if (j) {
            const HitPoint at = hits ? hits[j - 1] : HitPoint{0, 0};
            const PhotonSource::Surface surface = source_->surfaceAt(records[j - 1].triangle, at[0], at[1]);
            const uint32_t bounce = firstBounce_[s] + j - 1;
            const PhotonSource::Impact what =
                transmits ? PhotonSource::impact(surface, numbers.uniform(bounce + 1, rng_dim::kSurvival)) : PhotonSource::Impact::Reflects;
            power = PhotonSource::powerAfter(power, surface, what);
            scattered = scattered || what == PhotonSource::Impact::Reflects;
        }
        if (j < from) continue;
        const Record& r = records[j];
        Segment& x = *out++;
        x.origin = r.origin;
        x.direction = r.direction;
        x.length = r.length;
        x.power = power;
        x.triangle = r.triangle;
        x.path = pathOf_[s];
        x.bounce = uint16_t(firstBounce_[s] + j);
        x.scattered = scattered;
        x.impactDynamic = r.triangle != kNoTriangle ? source_->surface(r.triangle).dynamic : 0;
        x.impactVaries = r.triangle != kNoTriangle ? source_->surface(r.triangle).varies : 0;
        x.b1 = x.impactVaries ? hits[j][0] : 0.0f;
        x.b2 = x.impactVaries ? hits[j][1] : 0.0f;
    }
}

void TrackedPaths::segmentsOfSlots(uint32_t first, uint32_t last, std::vector<Segment>& out) const {
    for (uint32_t s = first; s < last; ++s) {
        const size_t at = out.size();
        out.resize(at + store_.slot(s).count);
        decode(s, 0, store_.slot(s).count, out.data() + at);
    }
}

int32_t TrackedPaths::slotOf(uint32_t path) const {
    const auto at = std::lower_bound(pathOf_.begin(), pathOf_.end(), path);
    return at != pathOf_.end() && *at == path ? int32_t(at - pathOf_.begin()) : -1;
}

void TrackedPaths::indexSlots(uint32_t first, uint32_t last) {
    const size_t chunks = (last - first + kChunk - 1) / kChunk;
    std::vector<CellsOfRun> runs(chunks);
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        CellsOfRun& run = runs[c];
        for (uint32_t s = first + uint32_t(c * kChunk); s < std::min<uint32_t>(last, first + uint32_t((c + 1) * kChunk)); ++s)
            for (uint32_t j = 0; j < store_.slot(s).count; ++j) {
                const Record& r = store_.at<0>(s, j);
                index_.cellsOf(r.origin, r.direction, reach(r), run.cells);
                run.cellsEnd.push_back(uint32_t(run.cells.size()));
            }
    });
    index_.list([&](auto&& emit) {
        for (size_t c = 0; c < chunks; ++c) {
            const CellsOfRun& run = runs[c];
            size_t n = 0;
            for (uint32_t s = first + uint32_t(c * kChunk); s < std::min<uint32_t>(last, first + uint32_t((c + 1) * kChunk)); ++s)
                for (uint32_t j = 0; j < store_.slot(s).count; ++j, ++n)
                    emit(SegmentRef{s, j, store_.generation(s)}, run.cells.data() + run.cellsBegin(n),
                         run.cellsEnd[n] - run.cellsBegin(n));
        }
    });
    for (uint32_t s = first; s < last; ++s)
        for (uint32_t j = 0; j < store_.slot(s).count; ++j) {
            const uint32_t triangle = store_.at<0>(s, j).triangle;
            if (triangle != kNoTriangle && source_->surface(triangle).dynamic)
                index_.listOnTriangle(triangle, SegmentRef{s, j, store_.generation(s)});
        }
}

uint64_t TrackedPaths::segmentsListedOn(const std::vector<uint32_t>& triangles) const {
    return index_.countListedOn(triangles, [&](const SegmentRef& r) { return isLive(r); });
}

AffectedPaths TrackedPaths::findAffected(const std::vector<uint32_t>& movedTriangles, const std::vector<uint8_t>& triangleMoved,
                                        const std::vector<Bounds3f>& newBounds, const SceneBvh& bvh, bool useGrid) {
    Stopwatch clock;
    AffectedPaths found;
    constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
    auto live = [&](const SegmentRef& r) { return isLive(r); };
    // Per affected path, the first place to retrace from: (slot, place).
    std::vector<std::pair<uint32_t, uint32_t>> byImpact;
    // (a) A segment that hit a triangle that moved: the photon would now land elsewhere.
    for (uint32_t triangle : movedTriangles)
        found.impactCandidates += index_.visitListedOn(triangle, live, [&](const SegmentRef& r) { byImpact.push_back({r.slot, r.place}); });
    auto firstPerPath = [](std::vector<std::pair<uint32_t, uint32_t>>& list) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
                   list.end());
    };
    firstPerPath(byImpact);
    found.byImpact = byImpact.size();

    // (b) A segment that a moved triangle now blocks before its impact. Only segments passing
    // through a moved object's new bounds can be; the grid lists them, the dynamic BVH decides,
    // counting moved triangles only (a deforming mesh's unmoved part blocks nothing new).
    // The test reaches a little past the impact: a tie there is the tracer's to decide, and
    // retracing a path that would not change repeats the full trace exactly.
    const float eps = bvh.rayEpsilon();
    std::vector<Bounds3f> boxes;
    for (const Bounds3f& b : newBounds) boxes.push_back(b.expanded(eps));
    auto blocked = [&](const Record& s) {
        const float end = s.triangle != kNoTriangle ? s.length + eps : s.length;
        // The grid lists whole cells: most candidates pass beside the moved bounds themselves.
        return rayMeetsAny(boxes, s.origin, s.direction, double(end)) &&
               bvh.movedOccludes(s.origin, s.direction, 0.0f, end, triangleMoved);
    };
    std::vector<std::pair<uint32_t, uint32_t>> candidates;  // (slot, place)
    if (useGrid) {
        index_.visitNear(boxes, live, [&](const SegmentRef& r) { candidates.push_back({r.slot, r.place}); });
    } else {
        for (uint32_t s = 0; s < trackedPaths(); ++s)
            for (uint32_t j = 0; j < store_.slot(s).count; ++j) {
                const Record& r = store_.at<0>(s, j);
                if (rayMeetsAny(boxes, r.origin, r.direction, double(r.length) + double(eps))) candidates.push_back({s, j});
            }
    }
    found.blockingCandidates = candidates.size();
    // A path that rule (a) retraces from this place or earlier changes the same way whether or
    // not the candidate is blocked: no need to ask.
    std::vector<uint32_t> fromImpact(trackedPaths(), kNone);
    for (const auto& [slot, place] : byImpact) fromImpact[slot] = place;
    std::vector<uint8_t> isBlocked(candidates.size(), 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const auto [slot, place] = candidates[i];
            isBlocked[i] = fromImpact[slot] > place && blocked(store_.at<0>(slot, place));
        }
    });
    std::vector<std::pair<uint32_t, uint32_t>> byBlocking;
    for (size_t i = 0; i < candidates.size(); ++i)
        if (isBlocked[i]) byBlocking.push_back(candidates[i]);
    firstPerPath(byBlocking);

    // Merge: per path the earlier of the two places; paths in increasing order (slots are).
    std::vector<AffectedPath>& affected = found.paths;
    affected.reserve(byImpact.size() + byBlocking.size());
    size_t i = 0, j = 0;
    while (i < byImpact.size() || j < byBlocking.size()) {
        uint32_t slot, place = kNone;
        if (j == byBlocking.size() || (i < byImpact.size() && byImpact[i].first < byBlocking[j].first)) {
            std::tie(slot, place) = byImpact[i++];
        } else if (i == byImpact.size() || byBlocking[j].first < byImpact[i].first) {
            std::tie(slot, place) = byBlocking[j++];
            ++found.byBlockingOnly;
        } else {
            slot = byImpact[i].first;
            place = std::min(byImpact[i++].second, byBlocking[j++].second);
        }
        affected.push_back({pathOf_[slot], firstBounce_[slot] + place, slot});
    }
    found.seconds = clock.seconds();
    return found;
}

// A retrace's new tails: per affected path (in order) its segments, and per segment the grid
// cells it passes, held in fixed chunks of paths.
struct TrackedPaths::NewTails {
    std::vector<CellsOfRun> runs;

    const CellsOfRun& runOf(size_t i) const { return runs[i / kChunk]; }
    uint32_t first(size_t i) const { return runOf(i).segmentsBegin(i % kChunk); }  // into runOf(i).segments
    uint32_t length(size_t i) const { return runOf(i).segmentsEnd[i % kChunk] - first(i); }
};

void TrackedPaths::retrace(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer, PathChanges& changes) {
    commit(affected, traceTails(affected, tracer), changes);
}

TrackedPaths::NewTails TrackedPaths::traceTails(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer) const {
    // From the segment each path is retraced from, with its numbers: fixed chunks of paths in
    // parallel, each writing its own run, so nothing depends on the schedule. The cells are
    // found here too (the index is only read).
    NewTails tails;
    tails.runs.resize((affected.size() + kChunk - 1) / kChunk);
    tbb::parallel_for(size_t(0), tails.runs.size(), [&](size_t c) {
        CellsOfRun& run = tails.runs[c];
        Segment start;
        for (size_t i = c * kChunk; i < std::min(affected.size(), (c + 1) * kChunk); ++i) {
            const AffectedPath& a = affected[i];
            const uint32_t place = a.bounce - firstBounce_[a.slot];
            decode(a.slot, place, place + 1, &start);
            tracer.continuePath(start.path, start.bounce, start.origin, start.direction, start.power, 0.0f, start.scattered,
                                run.segments);
            run.segmentsEnd.push_back(uint32_t(run.segments.size()));
        }
        for (const Segment& x : run.segments) {
            index_.cellsOf(x.origin, x.direction, reach(recordOf(x)), run.cells);
            run.cellsEnd.push_back(uint32_t(run.cells.size()));
        }
    });
    return tails;
}

void TrackedPaths::commit(const std::vector<AffectedPath>& affected, const NewTails& tails, PathChanges& changes) {
    auto keepOf = [&](size_t i) { return affected[i].bounce - firstBounce_[affected[i].slot]; };
    // Renumber first if a path would outgrow the references' places or a generation would wrap.
    uint32_t longest = 0;
    bool wraps = false;
    for (size_t i = 0; i < affected.size(); ++i) {
        longest = std::max(longest, keepOf(i) + tails.length(i));
        wraps = wraps || store_.wouldWrap(affected[i].slot);
    }
    if (!index_.layout().holds(longest)) renumber(SegmentRefLayout(trackedPaths(), longest));
    else if (wraps) renumber(index_.layout());

    // The old tails out, decoded before the new ones overwrite them.
    std::vector<uint64_t> removedAt(affected.size() + 1, changes.removed.size()), addedAt(affected.size() + 1, changes.added.size());
    for (size_t i = 0; i < affected.size(); ++i) {
        removedAt[i + 1] = removedAt[i] + store_.slot(affected[i].slot).count - keepOf(i);
        addedAt[i + 1] = addedAt[i] + tails.length(i);
    }
    changes.removed.resize(removedAt.back());
    changes.added.resize(addedAt.back());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, affected.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i)
            decode(affected[i].slot, keepOf(i), store_.slot(affected[i].slot).count, changes.removed.data() + removedAt[i]);
    });
    // Each path's place in the store, in path order (so the layout is the same for any thread
    // count; the store moves a path that outgrew its room); then each path writes only its own
    // records: in parallel.
    for (size_t i = 0; i < affected.size(); ++i) {
        store_.rewrite(affected[i].slot, keepOf(i), keepOf(i) + tails.length(i));
        retracedSinceSweep_[affected[i].slot >> 6] |= uint64_t(1) << (affected[i].slot & 63);
    }
    tbb::parallel_for(tbb::blocked_range<size_t>(0, affected.size(), 256), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) {
            const auto tail = tails.runOf(i).segments.begin() + tails.first(i);
            writeRecords(affected[i].slot, keepOf(i), &*tail, tails.length(i));
            std::copy_n(tail, tails.length(i), changes.added.begin() + int64_t(addedAt[i]));
        }
    });
    // The new segments listed: in the grid's cells (filled in parallel, each in path order), and
    // on the dynamic triangles they hit.
    auto forEachNew = [&](auto&& visit) {
        for (size_t i = 0; i < affected.size(); ++i)
            for (uint32_t j = 0; j < tails.length(i); ++j)
                visit(tails.runOf(i), tails.first(i) + j, SegmentRef{affected[i].slot, keepOf(i) + j, store_.generation(affected[i].slot)});
    };
    index_.list([&](auto&& emit) {
        forEachNew([&](const CellsOfRun& run, uint32_t n, const SegmentRef& ref) {
            emit(ref, run.cells.data() + run.cellsBegin(n), run.cellsEnd[n] - run.cellsBegin(n));
        });
    });
    forEachNew([&](const CellsOfRun& run, uint32_t n, const SegmentRef& ref) {
        const Segment& x = run.segments[n];
        if (x.hasImpact() && x.impactDynamic) index_.listOnTriangle(x.triangle, ref);
    });
    sweepIfStale();
}

void TrackedPaths::sweepIfStale() {
    // Only entries of paths retraced since the last sweep can be stale: the rest are kept on a
    // look at a bitmap that stays in cache, not at scattered records.
    if (index_.wantsSweep()) {
        index_.sweep([&](const SegmentRef& r) { return !(retracedSinceSweep_[r.slot >> 6] >> (r.slot & 63) & 1) || isLive(r); });
        std::fill(retracedSinceSweep_.begin(), retracedSinceSweep_.end(), uint64_t(0));
    }
    // References name slots and places, not positions: compacting the store keeps them.
    store_.compactIfWasteful();
}

void TrackedPaths::renumber(SegmentRefLayout layout) {
    index_.renumber(layout, [&](const SegmentRef& r) { return isLive(r); });
    store_.renumber(std::min(generations_, layout.generations()));
    std::fill(retracedSinceSweep_.begin(), retracedSinceSweep_.end(), uint64_t(0));
}

void TrackedPaths::segmentsNear(const std::vector<Bounds3f>& boxes, std::vector<Segment>& out) const {
    out.clear();
    std::vector<std::pair<uint32_t, uint32_t>> refs;  // (slot, place)
    index_.visitNear(boxes, [&](const SegmentRef& r) { return isLive(r); }, [&](const SegmentRef& r) { refs.push_back({r.slot, r.place}); });
    out.resize(refs.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, refs.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t i = r.begin(); i != r.end(); ++i) decode(refs[i].first, refs[i].second, refs[i].second + 1, &out[i]);
    });
}

size_t TrackedPaths::bytes() const {
    return store_.bytes() + pathOf_.capacity() * sizeof(uint32_t) + firstBounce_.capacity() * sizeof(uint16_t) +
           power_.capacity() * sizeof(Vec3f) + retracedSinceSweep_.capacity() * sizeof(uint64_t) + index_.bytes();
}

}  // namespace qsgi
