// The part of the ray cache that frames search (docs/design.md §6 steps 2–3 and 5): every path that
// meets the envelope, from its first segment that does. Finds the paths a move affects — from the
// first segment that hit a triangle that moved (rule a), or that a moved triangle now blocks
// before its impact (rule b) — and retraces them from there with the same random numbers, in two
// stages: the new tails are traced in parallel, then committed to the store and the index.
//
// The state has two owners: the records, one slot per tracked path in a SlottedPathStore, and the
// SegmentIndex that finds them. A record keeps what the photon source cannot say again, as the
// ray cache's later records do (ray_cache.h): origin, direction, length and impacted triangle, 32
// bytes. Power follows from the path's first tracked segment's, kept once per path, by the
// tracer's own arithmetic; path, bounce and the dynamic flag from the slot, the record's place
// and the triangle. Segments are handed out decoded.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "trace/envelope.h"
#include "trace/photon_tracer.h"
#include "trace/ray_cache.h"
#include "trace/scene_bvh.h"
#include "trace/segment_index.h"
#include "trace/slotted_path_store.h"

namespace qsgi {

// One affected path: retrace from segment `bounce`. slot: its slot among the tracked paths.
struct AffectedPath {
    uint32_t path;
    uint32_t bounce;
    uint32_t slot;
};

// The segments one frame's retrace exchanged: old tails and new tails, in path order.
// findAffected's answer: the paths, and what finding them took (the frame's record).
struct AffectedPaths {
    std::vector<AffectedPath> paths;
    uint64_t impactCandidates = 0;    // rule (a): tracked segments listed on the moved triangles
    uint64_t blockingCandidates = 0;  // rule (b): tracked segments the grid handed to the exact test
    uint64_t byImpact = 0;            // paths rule (a) found
    uint64_t byBlockingOnly = 0;      // paths rule (b) found and rule (a) did not
    double seconds = 0;
};

struct PathChanges {
    std::vector<Segment> removed, added;
};

class TrackedPaths {
public:
    // cache: a traced cache (it decodes with its photon source, which this object shares).
    // extension: how far past its impact a segment is followed for the envelope test
    // (envelopeMargin's reasoning); gridBounds and cellSize: the index's grid (what queries ask
    // about: the envelope's bounds) and cell edge. generations: how many times a path can be
    // retraced before every path is renumbered (at most what the references' bits allow; tests
    // lower it).
    TrackedPaths(const RayCache& cache, const Envelope& envelope, float extension, const Bounds3f& gridBounds,
                 float cellSize, uint32_t generations = kGenerations);
    // The same from the tails the tracer kept while tracing that cache (EnvelopeTails: the same
    // segments, found without decoding the cache), which it empties.
    TrackedPaths(std::shared_ptr<const PhotonSource> source, EnvelopeTails& tails, const Bounds3f& gridBounds, float cellSize,
                 uint32_t generations = kGenerations);
    static constexpr uint32_t kGenerations = SlottedPathStore<>::kMaxGenerations;

    // The paths the move from the previous pose to the current one affects, in increasing path
    // order. movedTriangles: the scene triangles any of whose vertices moved (sorted),
    // triangleMoved the same as flags; newBounds: the moved triangles' bounds in the current
    // pose; bvh: the current pose. useGrid = false tests every tracked segment (the baseline the
    // grid is measured against). Rule (a) reads the segments listed on the moved triangles, rule
    // (b) the grid's cells in the new bounds: neither scans the tracked segments. Drops the stale
    // entries it passes.
    AffectedPaths findAffected(const std::vector<uint32_t>& movedTriangles, const std::vector<uint8_t>& triangleMoved,
                               const std::vector<Bounds3f>& newBounds, const SceneBvh& bvh, bool useGrid);
    // Live tracked segments that impacted one of the triangles: what rule (a) will find, known
    // before any work, for the update's price.
    uint64_t segmentsListedOn(const std::vector<uint32_t>& triangles) const;
    // Index entries in the cells that overlap the boxes (SegmentIndex::entriesNear): a bound on
    // rule (b)'s candidates for a mover now in those boxes, known before any work.
    uint64_t entriesNear(const std::vector<Bounds3f>& boxes) const { return index_.entriesNear(boxes); }
    // Retraces the affected paths (findAffected's answer) and swaps their tails in; fills
    // changes.removed/added.
    void retrace(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer, PathChanges& changes);

    // The live tracked segments listed in the grid cells that overlap any of the boxes (with
    // their extension past the impact), each once, in the grid's order: the discs an update
    // recomputes. Visiting drops the stale entries of the visited cells (no answer changes), so
    // calls must not overlap.
    void segmentsNear(const std::vector<Bounds3f>& boxes, std::vector<Segment>& out) const;
    // The tracked segments of slots [first, last), in path order, appended.
    void segmentsOfSlots(uint32_t first, uint32_t last, std::vector<Segment>& out) const;
    void allSegments(std::vector<Segment>& out) const { segmentsOfSlots(0, uint32_t(trackedPaths()), out); }

    size_t trackedPaths() const { return pathOf_.size(); }
    uint64_t renumberings() const { return store_.renumberings(); }  // times every path was renumbered
    // A tracked path's slot: its index among the trackedPaths() in path order (fixed for this
    // object's life), −1 if the path is not tracked: for per-path state kept beside this one.
    int32_t slotOf(uint32_t path) const;
    size_t trackedSegments() const { return store_.records(); }
    size_t bytes() const;

private:
    // A tracked segment as stored: what the photon source cannot say again.
    struct Record {
        Vec3f origin, direction;
        float length;
        uint32_t triangle;
    };
    static Record recordOf(const Segment& s) { return {s.origin, s.direction, s.length, s.triangle}; }
    // Where an impact on a triangle whose albedo varies took place (Segment::b1, b2): a column
    // switched on only when the scene has such triangles.
    using HitPoint = std::array<float, 2>;
    // Writes tail segments [from, from + count) as slot s's records from place `at` on.
    void writeRecords(uint32_t s, uint32_t at, const Segment* from, uint32_t count);
    // Slot s's segments at places [from, to), decoded into out[0, to − from).
    void decode(uint32_t s, uint32_t from, uint32_t to, Segment* out) const;
    bool isLive(const SegmentRef& r) const { return store_.isLive(r.slot, r.place, r.generation); }
    // Both constructors: the store and the index from the tails, per block of paths in path
    // order (emptied).
    void keep(std::vector<std::vector<Segment>>& kept, const Bounds3f& gridBounds, float cellSize);
    double reach(const Record& r) const;  // how far along the ray the grid lists it
    // The retrace's two stages: the new tails traced (in parallel; nothing changes), then
    // committed to the store and the index (the old tails decoded into changes.removed first).
    struct NewTails;
    NewTails traceTails(const std::vector<AffectedPath>& affected, const PhotonTracer& tracer) const;
    void commit(const std::vector<AffectedPath>& affected, const NewTails& tails, PathChanges& changes);
    // Lists every segment of slots [first, last), cells found in parallel.
    void indexSlots(uint32_t first, uint32_t last);
    // Every generation back to 0, the index's references rewritten (in `layout`): before a
    // generation would wrap around, or a path outgrow the references' places.
    void renumber(SegmentRefLayout layout);
    // Drops stale index entries once they are worth a sweep, and compacts the store once
    // relocated paths left a quarter of it as garbage.
    void sweepIfStale();

    std::shared_ptr<const PhotonSource> source_;
    float extension_;
    uint32_t generations_;  // as asked; the store's limit is also bounded by the layout
    SlottedPathStore<Record, HitPoint> store_;
    // Per slot: the path, the bounce of its first tracked segment, and that segment's power.
    std::vector<uint32_t> pathOf_;  // increasing
    std::vector<uint16_t> firstBounce_;
    // Whether its first tracked segment's light was scattered (Segment::scattered): kept where
    // some surface lets photons through, else it is bounce > 0.
    std::vector<uint8_t> firstScattered_;
    bool firstScatteredAt(uint32_t s) const { return firstScattered_.empty() ? firstBounce_[s] > 0 : firstScattered_[s] != 0; }
    std::vector<Vec3f> power_;
    std::vector<uint64_t> retracedSinceSweep_;  // one bit per slot: its index entries may be stale
    // Mutable: queries drop stale entries as they pass them, which changes no answer.
    mutable SegmentIndex index_;
};

}  // namespace qsgi
