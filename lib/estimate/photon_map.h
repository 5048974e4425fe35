// Photon map (docs/design.md §5): the k nearest impacts h_s to vertex v that count for v, searched within
// `radius`; r_k is the distance to the k-th. An impact counts when it arrives from the front
// (d_s·n_v < 0) and — with disc regions — lies on a surface facing n_v (front face normal within
// 45°) between ε_v⁻ below and ε_v⁺ above v's tangent plane, so a panel under a ceiling or a plate
// over a floor lends the surface beneath none of its photons. E_v = Σ Φ_s over the k−1 impacts
// strictly inside r_k, divided by the area of the r_k disc that such surfaces cover (DiscRegions'
// covered cells; π r_k² where all are covered). The textbook form sums all k, which overestimates by
// k/(k−1); see estimate(). With fewer than k inside `radius`, all of them over the covered part
// of the radius disc. Without regions (the `paper` ablation, and vertices whose own surface is
// empty) the textbook rule: front-facing impacts over π r_k².
//
// The map owns a copy of its impacts and follows a changing photon set (docs/design.md §6.4): update()
// takes a frame's removed and added segments, and ballsHolding() names the vertices whose last
// estimate such a change can alter, so irradianceAt() recomputes only those. Two indexes answer
// the queries: a big kd-tree, built rarely, whose removed impacts are marked and skipped, and a
// uniform grid (a search radius across) over the impacts added since, rebuilt in linear time
// when they have changed: they churn every frame, where a tree's build would cost more than the
// queries it saves. Every answer is bit-identical to a
// map built from scratch over the same impacts, and to bruteForce(), the index-free reference.
//
// With afterFirstBounce (--direct exact: direct light is computed apart) the impacts of bounce-0
// segments never enter the map: its indexes, neighbour lists and changes hold only the impacts
// of later bounces, so every answer is that of a map over those alone.
#pragma once

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "estimate/disc_regions.h"
#include "estimate/fixed_point_power.h"
#include "estimate/point_grid.h"
#include "estimate/point_index.h"
#include "scene/scene.h"
#include "trace/ray_cache.h"
#include "util/work_counter.h"

namespace qsgi {

class PhotonMap {
public:
    // Copies the impacts of the cache's segments (their (path, bounce) must be unique) and builds
    // the kd-tree. bvh: the scene's triangles in the current pose, to decide impacts in mixed
    // cells; it must outlive the map (a refit in place is fine). afterFirstBounce: the impacts
    // of bounce-0 segments are left out, here and in every change.
    PhotonMap(const RayCache& cache, const Scene& scene, const SceneBvh* bvh, bool afterFirstBounce = false);

    // One frame's change of the photon set: the impacts of `removed` (found by (path, bounce);
    // they must be in the map) leave, those of `added` (not yet in it) enter; segments without an
    // impact (or, with afterFirstBounce, of bounce 0) are ignored. scene: the new pose, for the
    // triangles' front normals. Costs the changed impacts, plus now and then a rebuild of the big
    // tree (decided from counts alone).
    // A change that does not match the map throws std::logic_error and leaves it unusable.
    void update(const std::vector<Segment>& removed, const std::vector<Segment>& added, const Scene& scene);

    // Irradiance at every vertex, queries in `order` (a permutation of the vertices), in parallel.
    // regions: with coverage, for the scene's current pose; null for the textbook rule.
    // Records each vertex's ball for ballsHolding(), so calls on one map must not overlap.
    std::vector<Vec3f> irradiance(const Scene& scene, const DiscRegions* regions, float radius, int k,
                                  const std::vector<uint32_t>& order) const;
    // The same for the given vertices only, in that order: writes out[v] (out is resized to the
    // vertex count if needed; other entries are kept) and records their balls.
    // progress, if given, counts the vertices done.
    void irradianceAt(const Scene& scene, const DiscRegions* regions, float radius, int k,
                      const std::vector<uint32_t>& vertices, std::vector<Vec3f>& out, WorkCounter* progress = nullptr);
    // The same answers without an index: every vertex against every impact. Records nothing.
    std::vector<Vec3f> bruteForce(const Scene& scene, const DiscRegions* regions, float radius, int k) const;

    // The vertices (sorted) whose ball recorded by the last estimate holds an impact of
    // `changed` that counts for them: r_k² ≥ its distance², where r_k is the k-th counted
    // neighbour's distance (or the search radius when fewer were found), and the vertex's own
    // filter (front side, facing surface, height band, reachable cell) accepts it — an impact
    // the filter rejects never enters the vertex's estimate. Of the vertices that did not move
    // and whose regions did not change (the caller's to add), only these can see their estimate
    // change. The filter reads the map's triangle normals: call it with the removed impacts
    // before update() and with the added ones after. A vertex never estimated holds every
    // change. Not during an estimate.
    std::vector<uint32_t> ballsHolding(const Scene& scene, const DiscRegions* regions, const std::vector<Segment>& changed) const;

    // Neighbour lists, for a map that follows an animation: with them on, every estimate also
    // keeps the vertex's *list* — every counted impact within a bound at least as far as its
    // k-th (the candidates its query tested) — and editLists() keeps each list exact through a
    // change, so that irradianceAt() estimates a vertex from its list alone, and queries the
    // trees again only where a list fell short of k inside its bound, or was forgotten.
    void keepLists(bool on) { keepLists_ = on; }
    // Removed impacts (entering = false; judged as ballsHolding judges them: before update())
    // leave the lists that hold them, added ones (after update()) enter the lists whose bound
    // holds them and that they count for. Returns the vertices whose list changed or that have
    // none (sorted): those whose estimate may change.
    std::vector<uint32_t> editLists(const Scene& scene, const DiscRegions* regions, const std::vector<Segment>& changed,
                                    bool entering, int k);
    // The vertices' lists no longer hold (they moved, or their filter changed): their next
    // estimate queries the trees.
    void forget(const std::vector<uint32_t>& vertices);
    // Of the vertices the last irradianceAt() estimated, how many it queried the trees for.
    size_t lastQueries() const { return lastQueries_; }
    // Bytes of the neighbour lists.
    size_t listBytes() const;

    size_t size() const { return impacts_.size() - bigRemoved_; }  // live impacts

private:
    struct Impact {
        Vec3f point;  // Segment::impactPoint(), the same bits
        Vec3f direction;
        Vec3f power;
        uint32_t triangle;
        uint64_t key;  // path << 16 | bounce: the order of equal distances
    };
    static uint64_t keyOf(const Segment& s) { return uint64_t(s.path) << 16 | s.bounce; }
    static Impact impactOf(const Segment& s);
    // Whether the segment's impact belongs in the map: it has one, and after the first bounce
    // when only those count.
    bool takes(const Segment& s) const { return s.hasImpact() && !(afterFirstBounce_ && !s.scattered); }
    // The impacts of the segments the map holds, and their points.
    void impactsOf(const std::vector<Segment>& segments, std::vector<Impact>& impacts, std::vector<Vec3f>& points) const;

    // Equal distances are ordered by (path, bounce), never by where the impacts are stored: the k
    // nearest are the same set whatever order the cache holds them in or updates left them in.
    struct Neighbour {
        float distanceSquared;
        uint64_t key;
        Vec3f power;
        bool operator<(const Neighbour& o) const {
            return distanceSquared < o.distanceSquared || (distanceSquared == o.distanceSquared && key < o.key);
        }
    };
    // Whether an impact counts for vertex v (front side, and v's own band with regions).
    struct VertexFilter {
        Vec3d position, normal;
        const VertexDisc* disc;  // null: front side only
        float radius;            // the regions' disc radius
    };
    VertexFilter filterFor(const Scene& scene, const DiscRegions* regions, size_t v) const;
    bool counts(const VertexFilter& f, const Impact& impact) const;
    // E from the counted neighbours, the first `sorted` of them nearest first (at least min(k,
    // all) of them).
    Vec3f estimate(const std::vector<Neighbour>& sortedCounted, size_t sorted, const VertexDisc* disc, float radius, int k) const;
    void estimateAt(const Scene& scene, const DiscRegions* regions, float radius, int k,
                    const std::vector<uint32_t>& vertices, std::vector<Vec3f>& out, WorkCounter* progress = nullptr) const;
    struct NeighbourList;
    struct QueryScratch {  // reused across one thread's queries
        std::vector<size_t> indices;
        std::vector<float> d2;
        std::vector<std::pair<float, uint32_t>> candidates;
    };
    // The counted impacts a query of the trees finds for a vertex at p (at least the k nearest
    // within the radius), unsorted; and, if given, the list they make.
    void nearestCounted(const Vec3f& p, const VertexFilter& filter, float radiusSquared, int k, size_t bigLive,
                        size_t most, QueryScratch& scratch, std::vector<Neighbour>& front, NeighbourList* list) const;

    // Slot of the live impact with this key in the big tree, or -1.
    int64_t bigSlot(uint64_t key) const;
    void removeImpact(uint64_t key);
    void addImpact(const Segment& s);
    void rebuildBig();    // every live impact into the big tree; the small one empties
    // The grid over the impacts added since rebuildBig(), cells `cell` across (queries ask it
    // for every added impact within their radius).
    void rebuildSmall(float cell) const;

    // [0, bigCount_): the big tree's points, tree index = slot; then the added ones, small tree
    // index = slot − bigCount_. Removed slots of the big part stay until the next rebuildBig().
    std::vector<Impact> impacts_;
    size_t bigCount_ = 0;
    std::vector<uint8_t> bigDead_;                       // per big slot
    size_t bigRemoved_ = 0;                              // dead big slots
    std::vector<std::pair<uint64_t, uint32_t>> bigKeys_;  // (key, big slot), sorted
    std::unordered_map<uint64_t, uint32_t> smallSlots_;   // key → slot of an added impact
    std::unique_ptr<PointIndex> big_;
    // Built when a query needs it (estimates are const for their one-shot callers).
    mutable std::unique_ptr<PointGrid> small_;
    mutable float smallCell_ = 0;
    mutable bool smallStale_ = false;

    // Per vertex, r_k² of its last estimate; +inf: never estimated; < 0: no ball (k ≤ 0).
    // irradiance() is const for its one-shot callers; recording changes none of its answers.
    mutable std::vector<float> ballsSquared_;

    // Every counted impact at distance² < bound (≤ bound where inclusive: the search radius),
    // unsorted. Valid lists hold exactly that set.
    struct NeighbourList {
        std::vector<Neighbour> counted;
        float bound = 0;
        bool inclusive = false;
        bool valid = false;
        bool holds(float distanceSquared) const { return inclusive ? distanceSquared <= bound : distanceSquared < bound; }
    };
    bool keepLists_ = false;
    mutable std::vector<NeighbourList> lists_;  // per vertex, with keepLists_ (estimates write them)
    mutable size_t lastQueries_ = 0;

    std::vector<Vec3f> frontNormals_;
    const SceneBvh* bvh_;  // of the impacted triangles, for the 45° test
    PowerQuantizer quantizer_;
    bool afterFirstBounce_;  // impacts of bounce-0 segments stay out
};

}  // namespace qsgi
