// Density estimation on the tangent plane (docs/design.md §5, Lastra et al. 2002). Vertex v owns the disc
// D_v = { p : (p − v)·n_v = 0, |p − v| ≤ r }. A segment s crosses it when d·n_v < 0 and its line
// meets the plane at t* inside the disc, with
//   clip / linear: 0 < t* ≤ t_s + min(ε_v⁺/|d·n_v|, r) — its impact lies at most ε_v⁺ (the height
//                  of v's own surface) in front of the plane, so a panel 1 cm under a ceiling does
//                  not leak through it — and no upper limit for an escaping photon (it keeps going
//                  past the scene, so discs at an open edge see the photons that pass beside it);
//                  the crossing must also fall in a cell reachable from v's side (DiscRegions);
//   paper:         0 < t* ≤ t_s + r, every crossing counts (the published rule, for ablations).
// E_v = Σ Φ / A_v with A_v = πr² × reachable cells / all cells (clip), or πr² (paper). `linear`
// takes the constant term of a least-squares linear fit of the flux density over the reachable
// cells instead, which removes the first-order bias where part of the disc is unreachable.
// Vertices with an empty own surface use the paper rule (counted in the log).
//
// detpCrossing is the definition. The Embree index traces each segment through oriented discs at
// the vertices (slightly enlarged, so it finds a superset) and keeps exactly what detpCrossing
// accepts; brute force applies detpCrossing to every pair. Both count the same set, and
// fixed-point sums make them equal to the last bit.
//
// afterFirstBounce (--direct exact: direct light is computed apart): segments of bounce 0 cross
// no disc. They are left out where crossings are found, not taken out of the segment lists, so
// a list's indexes (findCrossings' `segment`, an update's remembered bounces) stay those of the
// segments given.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <initializer_list>
#include <utility>
#include <vector>

#include "estimate/detp_settings.h"
#include "estimate/disc_regions.h"
#include "estimate/fixed_point_power.h"
#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/ray_cache.h"
#include "util/enum_names.h"
#include "util/work_counter.h"

namespace qsgi {

// Where a segment crosses a disc: (x, y) in units of r in the disc's frame, and the cell there.
struct DiscCrossing {
    double x = 0, y = 0;
    int cell = 0;
};

// The definition. disc: the vertex's regions (its fallback flag switches to the paper rule).
// Reach::TestPoint: the crossing lies in a mixed cell and counts if pointReachable says so
// (kept apart so that the Embree index can test it after its traversal).
Reach detpCrossing(const Segment& s, const Vec3f& centre, const Vec3f& normal, const VertexDisc& disc, float radius,
                   DetpBoundary rule, DiscCrossing& where);
// detpCrossing with a mixed cell's point decided.
bool detpCounts(const Segment& s, const Vec3f& centre, const Vec3f& normal, const VertexDisc& disc, float radius,
                DetpBoundary rule, const SceneBvh* bvh, DiscCrossing& where);

struct DetpQueryStats {
    uint64_t discHits = 0;  // accepted (segment, disc) pairs
};

// One vertex's fixed-point sums: Σ Φ and, for `linear`, Σ Φ·x and Σ Φ·y (x, y in units of r,
// quantised to 2^-20). Integers, so sums are order-independent, and "+ new − old" is exact.
struct DetpVertexSums {
    __extension__ typedef __int128 Int128;
    PowerSum power;
    Int128 x[3] = {0, 0, 0}, y[3] = {0, 0, 0};

    void add(const Vec3f& phi, const DiscCrossing& at, const PowerQuantizer& q, bool moments, int sign = 1);
    // The same with the crossing's coordinates already quantised (momentOf): what an update
    // remembers of a crossing, so that it can leave the sums exactly as it entered them.
    void add(const Vec3f& phi, int32_t qx, int32_t qy, const PowerQuantizer& q, bool moments, int sign);
    static int32_t momentOf(double coordinate);
    DetpVertexSums& operator+=(const DetpVertexSums& o);
    DetpVertexSums& operator-=(const DetpVertexSums& o);
    bool operator==(const DetpVertexSums& o) const;
};

// E_v from its sums and disc (the rule's area or linear fit).
Vec3f detpVertexIrradiance(const DetpVertexSums& sums, const VertexDisc* disc, float radius, DetpBoundary rule,
                           const PowerQuantizer& q);

// One crossing found by DetpDiscs::findCrossings: segment i of the list crossed vertex v's disc.
struct SegmentCrossing {
    uint32_t segment;
    uint32_t vertex;
    DiscCrossing at;
};

class DetpDiscs {
public:
    // Builds the disc BVHs: the discs that never move once, the others (`refitted`, per scene
    // vertex; the dynamic vertices when null) refitted by updateDynamic. An incremental update
    // puts there every vertex a move can ever touch, so that the other discs' crossings never
    // change and can be remembered. regions (and bvh, the scene's triangles) may be null for the
    // paper rule; both are read at query time, so they must hold the pose being queried.
    // afterFirstBounce: every query below finds no crossing for a segment of bounce 0.
    DetpDiscs(const EmbreeDevice& device, const Scene& scene, float radius, DetpBoundary rule, const DiscRegions* regions,
              const SceneBvh* bvh, const std::vector<uint8_t>* refitted = nullptr, bool afterFirstBounce = false);

    // Moves the refitted discs to the scene's current pose.
    void updateDynamic();

    // Every vertex's sums from the given segments (traced in that order), in parallel.
    std::vector<DetpVertexSums> sums(const std::vector<Segment>& segments, const PowerQuantizer& q,
                                     DetpQueryStats* stats = nullptr) const;
    // The same from every segment of the cache, decoded a group of blocks at a time and, with
    // `morton`, traced in the Morton order of their end points within the group (coherent
    // tracing: most discs a segment crosses sit around its end). Integer sums: the bits do not
    // depend on the order.
    // progress, if given, counts the segments done.
    std::vector<DetpVertexSums> sums(const RayCache& cache, bool morton, const PowerQuantizer& q,
                                     DetpQueryStats* stats = nullptr, WorkCounter* progress = nullptr) const;

    // Every crossing of the given segments with the discs of `which`, decided exactly. Found in
    // parallel; the list is in segment order, each segment's crossings by vertex, the same for
    // any thread count.
    enum class Discs { All, Refitted, Fixed };
    void findCrossings(const std::vector<Segment>& segments, Discs which, std::vector<SegmentCrossing>& out) const;

    // The sums of the given vertices from the given segments (an update's touched vertices):
    // a disc BVH of just those vertices, built for the call, that each segment is traced through.
    void recompute(const std::vector<const Segment*>& segments, const PowerQuantizer& q,
                   const std::vector<uint32_t>& vertices, std::vector<DetpVertexSums>& sums) const;

private:
    struct Crossed;
    void addCrossings(const std::vector<Segment>& segments, const PowerQuantizer& q,
                      tbb::enumerable_thread_specific<std::vector<DetpVertexSums>>& perThread,
                      tbb::enumerable_thread_specific<uint64_t>& hitCount, WorkCounter* progress = nullptr) const;
    struct Part {
        std::vector<uint32_t> vertices;  // primID -> scene vertex
        unsigned geomId = RTC_INVALID_GEOMETRY_ID;
    };
    // The discs the segment crosses in the given disc BVHs, sorted by vertex, decided.
    void crossings(const Segment& s, std::vector<Crossed>& out) const;
    void crossingsIn(const Segment& s, std::initializer_list<std::pair<RTCScene, const Part*>> bvhs,
                     std::vector<Crossed>& out) const;
    void addPart(const EmbreeDevice& device, RTCScene target, Part& part, RTCBuildQuality quality) const;
    void fillPart(RTCGeometry geom, const Part& part) const;

    const EmbreeDevice& device_;
    const Scene& scene_;
    float radius_;
    DetpBoundary rule_;
    const DiscRegions* regions_;
    const SceneBvh* bvh_;
    bool afterFirstBounce_;
    float rayExtension_;  // lets Embree's float tests see crossings at t* ≈ 0 and at the rule's end
    float searchRadius_;  // the discs in Embree, slightly enlarged (a superset of the exact test)
    Bounds3f escapeBounds_;  // escaping segments are traced until they leave this box
    std::vector<uint8_t> refitted_;
    EmbreeScene staticDiscs_, dynamicDiscs_;
    Part static_, dynamic_;
};

// One vertex's sums from the given segments (the exact test on each; an update's recomputed
// vertices, with the segments the tracked-path grid lists near the disc). afterFirstBounce, here
// and below: segments of bounce 0 cross nothing.
DetpVertexSums detpVertexSums(const Scene& scene, uint32_t vertex, const std::vector<const Segment*>& segments, float radius,
                              DetpBoundary rule, const DiscRegions* regions, const SceneBvh* bvh, const PowerQuantizer& q,
                              bool afterFirstBounce = false);

// Index-free reference: every segment against every disc.
std::vector<Vec3f> detpBruteForce(const Scene& scene, const RayCache& cache, float radius, DetpBoundary rule,
                                  const DiscRegions* regions, const SceneBvh* bvh, bool afterFirstBounce = false);

// Approximate DETP (--detp-index flann): candidates are the segments whose impact lies within
// radius·(1 + kFlannCandidateMargin) of the vertex, then the exact test. It misses segments that
// cross a disc but land far away (silhouettes, convex edges, escaping photons).
constexpr float kFlannCandidateMargin = 0.25f;
// With afterFirstBounce the index holds the impacts of later segments only.
std::vector<Vec3f> detpFlannCandidates(const Scene& scene, const RayCache& cache, float radius, DetpBoundary rule,
                                       const DiscRegions* regions, const SceneBvh* bvh,
                                       const std::vector<uint32_t>& vertexOrder, bool afterFirstBounce = false);

// The segments of blocks [beginBlock, endBlock) of the cache, decoded, in the order DETP traces
// them through the discs: the Morton order of their end points, or the cache's own.
std::vector<Segment> segmentsInQueryOrder(const RayCache& cache, size_t beginBlock, size_t endBlock, bool morton);

}  // namespace qsgi
