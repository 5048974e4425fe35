// The part of the ray cache that frames search (docs/design.md §6 steps 2–3 and 5): every path that meets
// the envelope, from its first segment that does. Finds the paths a move affects — from the first
// segment that hit a triangle that moved, or that a moved triangle now blocks before its impact —
// retraces them from there with the same random numbers, and swaps the new tails in.
#pragma once

#include <cstdint>
#include <vector>

#include "trace/envelope.h"
#include "trace/photon_tracer.h"
#include "trace/ray_cache.h"
#include "trace/scene_bvh.h"
#include "trace/segment_grid.h"
#include "util/frame_timing.h"

namespace qsgi {

// One affected path: retrace from segment `bounce`.
struct AffectedPath {
    uint32_t path;
    uint32_t bounce;
};

// The segments one frame's retrace exchanged: old tails and new tails, in path order.
struct PathChanges {
    std::vector<Segment> removed, added;
};

class TrackedPaths {
public:
    // extension: how far past its impact a segment is followed for the envelope test
    // (envelopeMargin's reasoning); gridBounds and cellSize: the segment grid's region (what
    // queries ask about: the envelope's bounds) and cell edge. generations: how many times a path
    // can be retraced before every path is renumbered (SegmentRef's 16 bits; tests lower it).
    TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                 float cellSize, uint32_t generations = kGenerations);
    static constexpr uint32_t kGenerations = 1u << 16;

    // The paths the move from the previous pose to the current one affects. movedTriangles: the
    // scene triangles any of whose vertices moved (sorted), triangleMoved the same as flags;
    // newBounds: the moved triangles' bounds in the current pose; bvh: the current pose.
    // useGrid = false tests every tracked segment (the baseline the grid is measured against).
    // Rule (a) reads the segments listed on the moved triangles, rule (b) the grid's cells in
    // the new bounds: neither scans the tracked segments. Counts and time go to `stats`. Drops
    // the stale entries it passes.
    std::vector<AffectedPath> findAffected(const std::vector<uint32_t>& movedTriangles, const std::vector<uint8_t>& triangleMoved,
                                           const std::vector<Bounds3f>& newBounds, const SceneBvh& bvh, bool useGrid,
                                           FrameTiming& stats);
    // Live tracked segments that impacted one of the triangles: what rule (a) will find, known
    // before any work, for the update's price.
    uint64_t segmentsListedOn(const std::vector<uint32_t>& triangles) const;
    // Retraces the affected paths and swaps their tails in; fills changes.removed/added.
    void retrace(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer, PathChanges& changes, FrameTiming& stats);

    // The live tracked segments listed in the grid cells that overlap any of the boxes (with
    // their extension past the impact), each once, in the grid's order: for the blocking test
    // and the discs an update recomputes. And the segment a reference names (valid until the
    // next retrace).
    // Visiting drops the stale entries of the visited cells (no answer changes), so calls must
    // not overlap.
    void refsNear(const std::vector<Bounds3f>& boxes, std::vector<SegmentRef>& out) const;
    const Segment& segment(const SegmentRef& r) const { return *segmentOf(r); }
    // Every tracked segment, in path order (valid until the next retrace).
    void allSegments(std::vector<const Segment*>& out) const;

    size_t trackedPaths() const { return paths_.size(); }
    uint64_t renumberings() const { return renumberings_; }  // times every path was renumbered
    // A tracked path's index among the trackedPaths() (fixed for this object's life), −1 if the
    // path is not tracked: for per-path state kept beside this one.
    int32_t slotOf(uint32_t path) const { return path < slot_.size() ? slot_[path] : -1; }
    size_t trackedSegments() const { return liveSegments_; }
    size_t bytes() const;

private:
    // A tracked path's segments sit in segments_[begin, begin + count), room for `capacity`. A
    // retrace writes the new tail over the old one when it fits (the kept head stays where it
    // is, and stays listed), and moves the path to the end of the store, with some room to
    // spare, when it does not.
    struct Tracked {
        uint32_t path;
        uint16_t generation = 0;  // of its newest segments: bumped by each retrace
        uint16_t firstBounce;     // the first segment kept: the first that meets the envelope
        uint64_t begin;           // into segments_
        uint32_t count;
        uint32_t capacity;
    };
    // The reference to segment j of t as it is now.
    SegmentRef refOf(const Tracked& t, uint32_t j) const {
        return SegmentRef{t.path, generation_[t.begin + j], uint16_t(t.firstBounce + j)};
    }
    const Segment* segmentOf(const SegmentRef& r) const;
    bool isLive(const SegmentRef& r) const;
    void index(const Tracked& t);
    // Lists segment j of t in the given grid cells, and on its triangle if dynamic.
    void indexSegment(const Tracked& t, uint32_t j, const uint32_t* cells, size_t cellCount);
    void listOnTriangle(const Tracked& t, uint32_t j);
    double reach(const Segment& s) const;  // how far along the ray the grid lists it

    // Drops stale entries from the grid and the per-triangle lists once they are a quarter of the
    // live ones, and compacts the store once moved paths left a quarter of its live size as
    // garbage: these stores are most of a long run's memory.
    void sweepIfStale();
    // Every path's generation back to 0, and the grid and per-triangle lists rebuilt from the
    // live segments: before a path's generation would wrap around.
    void renumber();

    Envelope envelope_;
    float extension_;
    uint32_t generations_;
    uint64_t renumberings_ = 0;
    std::vector<Segment> segments_;  // tracked tails; paths that outgrew their room leave garbage
    // Per slot of segments_: the generation its segment was written in (a reference is live if
    // it names that generation), and how many grid cells list it.
    std::vector<uint16_t> generation_;
    std::vector<uint16_t> cellCount_;
    size_t garbage_ = 0;             // slots of segments_ no path owns
    mutable size_t gridEntries_ = 0;  // listed in the grid, stale ones included
    size_t liveGridEntries_ = 0;
    std::vector<Tracked> paths_;     // increasing path id
    std::vector<int32_t> slot_;      // path id -> index in paths_, −1 if untracked
    std::vector<uint64_t> retracedSinceSweep_;  // one bit per path id: its grid entries may be stale
    size_t liveSegments_ = 0;
    // Mutable: refsNear drops stale entries as it passes them, which changes no answer.
    mutable SegmentGrid grid_;
    // Per scene triangle, the tracked segments that impacted it (dynamic triangles only): rule (a).
    std::vector<std::vector<SegmentRef>> byTriangle_;
};

}  // namespace qsgi
