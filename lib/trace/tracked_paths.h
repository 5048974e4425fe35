// The part of the ray cache that frames search (DESIGN §6 steps 2–3 and 5): every path that meets
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

namespace qsgi {

// One affected path: retrace from segment `bounce`.
struct AffectedPath {
    uint32_t path;
    uint32_t bounce;
};

// What one frame's update changed, for the estimators and timing.json.
struct PathChanges {
    std::vector<Segment> removed, added;  // old tails and new tails, path order
    uint64_t pathsRetraced = 0;
    uint64_t affectedByImpact = 0, affectedByBlocking = 0;  // (a) and (b) of DESIGN §6 step 2
    uint64_t blockingCandidates = 0;                         // segments the grid handed to the exact test
    double findSeconds = 0, retraceSeconds = 0;
};

class TrackedPaths {
public:
    // extension: how far past its impact a segment is followed for the envelope test
    // (envelopeMargin's reasoning); gridBounds and cellSize: the segment grid's region (what
    // queries ask about: the envelope's bounds) and cell edge.
    // untracked, if given, receives every segment that is not tracked.
    TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                 float cellSize, std::vector<Segment>* untracked = nullptr);

    // The paths the move from the previous pose to the current one affects. triangleMoved: per
    // scene triangle, whether any of its vertices moved; newBounds: the moved instances' bounds in
    // the current pose; bvh: the current pose. useGrid = false tests every tracked segment (the
    // baseline the grid is measured against).
    std::vector<AffectedPath> findAffected(const std::vector<uint8_t>& triangleMoved, const std::vector<Bounds3f>& newBounds,
                                           const SceneBvh& bvh, bool useGrid, PathChanges& changes) const;
    // Retraces the affected paths and swaps their tails in; fills changes.removed/added.
    void retrace(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer, PathChanges& changes);

    // Tracked segments that pass through the box (with their extension), for the discs an update
    // recomputes. Appends pointers valid until the next retrace.
    void segmentsNear(const Bounds3f& box, std::vector<const Segment*>& out) const;
    // Every tracked segment (for estimators that rebuild from all of them).
    void appendAll(std::vector<Segment>& out) const;
    void allSegments(std::vector<const Segment*>& out) const;

    size_t trackedPaths() const { return paths_.size(); }
    size_t trackedSegments() const { return liveSegments_; }
    size_t bytes() const;

private:
    struct Tracked {
        uint32_t path;
        uint32_t generation = 0;
        uint32_t firstBounce;  // the first segment kept: the first that meets the envelope
        uint64_t begin;        // into segments_
        uint32_t count;
    };
    const Segment* segmentOf(const SegmentRef& r) const;
    bool isLive(const SegmentRef& r) const;
    void index(const Tracked& t);
    double reach(const Segment& s) const;  // how far along the ray the grid lists it

    Envelope envelope_;
    float extension_;
    std::vector<Segment> segments_;  // tracked tails, appended; retraced paths leave garbage
    std::vector<Tracked> paths_;     // increasing path id
    std::vector<int32_t> slot_;      // path id -> index in paths_, −1 if untracked
    size_t liveSegments_ = 0;
    SegmentGrid grid_;
};

}  // namespace qsgi
