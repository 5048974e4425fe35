// The scene's triangles in Embree (docs/design.md §6 steps 0–1): static triangles in one Embree scene
// built once per run and never rebuilt, dynamic triangles in another that is refitted when the
// animation moves them. A ray's closest hit is the nearer of the two scenes' hits; at equal t the
// lower scene triangle id wins, inside each scene too (an intersection filter), so which triangle
// a ray hits never depends on a BVH's shape or traversal order. Full recomputation, incremental
// retraces and camera rays all go through intersect(), so they see identical hits.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "scene/scene.h"
#include "scene/surface_lookup.h"
#include "trace/embree_device.h"

namespace qsgi {

struct SurfaceHit {
    float t = 0;
    uint32_t triangle = 0;  // scene triangle index
    float u = 0, v = 0;     // barycentrics of vertices 1 and 2 of that triangle
    Vec3f ng;               // Embree's geometric normal: unnormalised, out of the front (CCW) side
};

// The tie rule's per-query state and filter, as SceneBvh installs them on its triangles: a
// closest-hit query passes a TieBreakContext (rtcInitIntersectContext on `base`). Public so that
// the benchmarks' Embree ceiling traces with exactly the tracer's configuration.
struct TieBreakContext {
    RTCIntersectContext base;  // first member: Embree hands back a pointer to it
    float bestT = std::numeric_limits<float>::infinity();
    unsigned bestPrim = RTC_INVALID_GEOMETRY_ID;
    bool blendStops = false;  // a BLEND surface stops the ray (transmittance() weighs it instead)
};
void lowestPrimitiveOnTies(const RTCFilterFunctionNArguments* args);

// Where light passes through a surface (issue 57): an alpha-MASK cut-out, or a BLEND's share
// 1 − alpha. Every ray — photons, shadow and gather rays, start points, cover tests, the camera —
// ignores a hit where the material does not stop it (SurfaceLookup::stops), inside Embree's
// filters: the answer at a hit is a pure function of the ray (its origin and direction) and the
// triangle, never of the order in which traversal meets hits, so a refitted and a rebuilt BVH,
// and a retrace and a first trace, see the same surfaces. A BLEND's choice is a hash of the
// ray's origin, direction and triangle: each ray decides once and for all, independently of the
// next.
//
// The back side of a doubleSided surface (lib/scene/back_sides.h) is a triangle of its own where
// its front is: a ray passes the one of the two that turns its back to it, and meets the other.
struct PassThrough {
    std::shared_ptr<const SurfaceLookup> lookup;
    std::vector<uint32_t> sceneTriangle;  // Embree primID -> scene triangle (the part's)
    // Per primID: +1 when a two-sided triangle's front (Scene::frontFaceNormals) is the side
    // Embree's Ng points out of, −1 when it is the other, 0 for a one-sided triangle; empty when
    // the part has no two-sided triangle.
    std::vector<int8_t> frontAlongNg;
};
// A ray's own choice in [0, 1) at a scene triangle, for one `purpose` (BLEND's, a pane's: two
// independent numbers for a surface that is both).
enum class RayChoice : uint64_t { Blend = 0, Pane = 0x9E3779B97F4A7C15ull };
float rayChoice(const Vec3f& origin, const Vec3f& direction, uint32_t triangle, RayChoice purpose);

// staticGeometryRises' test of one triangle: its box comes within `radius` of `centre`, and a
// corner lies at `height` or more above `centre` along `normal`. Shared with OwnSurfaceTree's
// answer to the same question, so that both say the same of every triangle they look at.
bool triangleRisesNear(const Vec3f corners[3], const Vec3f& centre, float radius, const Vec3d& normal, double height);

class SceneBvh {
public:
    // Build it from the rest pose (before any frame is applied), so that every run — whatever
    // its first frame — refits the same dynamic BVH.
    SceneBvh(const EmbreeDevice& device, const Scene& scene);

    // Re-reads the dynamic vertices from the scene and refits the dynamic geometry.
    void updateDynamic(const Scene& scene);

    std::optional<SurfaceHit> intersect(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const;
    // intersect(), BLEND surfaces stopping the ray when `blendStops` (the camera composites them
    // by their alpha; transmittance() weighs them).
    std::optional<SurfaceHit> closestHit(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar,
                                         bool blendStops) const;
    // The closest hit, passing straight through a pane (KHR_materials_transmission) where the
    // ray's own choice says so: with probability T at the pane (rayChoice of the ray and the
    // pane's triangle; at most kMostPanes panes). The final gather's rays.
    std::optional<SurfaceHit> intersectThroughPanes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const;
    // What reaches the end of the segment (tnear, tfar): 0 where an opaque surface blocks it,
    // else the product, in order, of what each surface it crosses lets through (1 if none): a
    // pane's T × base colour, a BLEND's 1 − alpha (its expectation, free of the per-ray choice's
    // noise). Shadow rays.
    Vec3f transmittance(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const;
    // Some surface lets a share of the light through (a pane or a BLEND): shadow rays then ask
    // transmittance() rather than occluded().
    bool passesShares() const { return surfaces_->anyTransmits() || surfaces_->anyBlends(); }
    static constexpr int kMostPanes = 16;
    // True if any geometry blocks the ray within (tnear, tfar).
    bool occluded(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const;
    // True if the static geometry alone blocks the ray within (tnear, tfar): occluded() is this
    // or dynamicOccludes(), so a caller may keep static answers across frames.
    bool staticOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const;
    // staticOccludes for up to 16 rays at once, each over (0, tfar], traced by Embree as one
    // packet: rays that start at one point and fan out, as a disc's do, share most of their
    // traversal (disc regions on data/cornell 16 -> 13 µs a vertex, on the FlightHelmet room
    // 110 -> 83, the same bytes). Bit i of the answer is ray i's.
    struct RayPacket {
        static constexpr int kMaxRays = 16;
        int count = 0;
        std::array<Vec3f, kMaxRays> origin, direction;
        std::array<float, kMaxRays> tfar;
        void add(const Vec3f& o, const Vec3f& d, float end) {
            origin[size_t(count)] = o;
            direction[size_t(count)] = d;
            tfar[size_t(count++)] = end;
        }
    };
    uint32_t staticOccludesPacket(const RayPacket& rays) const;
    // False only if no static triangle that comes within `radius` of `centre` has a corner at
    // `height` or more above `centre`, heights measured along `normal` (an Embree
    // point query, tested on each triangle's box: true may be said of a triangle a little
    // farther). A ray that stays within the ball and higher than `height` above the plane
    // (a triangle's highest point is a corner) is then never blocked by static geometry; with
    // height −∞, any ray within the ball. Past 2048 triangles near it says true without looking
    // further (a bound on its cost: a conservative answer).
    bool staticGeometryRises(const Vec3f& centre, float radius, const Vec3f& normal, double height) const;
    // How many triangles near staticGeometryRises looks at before it says "rises": where it is
    // asked (the disc regions' shortcut) tracing the rays is then the cheaper way to the answer.
    static constexpr uint32_t kMostTrianglesNear = 2048;
    // True if the dynamic geometry alone blocks the ray within (tnear, tfar].
    bool dynamicOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar) const;
    // The same, counting only the triangles flagged in triangleMoved (by scene triangle).
    bool movedOccludes(const Vec3f& origin, const Vec3f& direction, float tnear, float tfar,
                       const std::vector<uint8_t>& triangleMoved) const;

    // Offset that lifts spawned rays off surfaces: scaled with the scene, never with metres.
    float rayEpsilon() const { return rayEpsilon_; }
    // What the materials say at a point (lib/scene/surface_lookup.h): the one lookup of the scene's
    // surfaces, which the filters, the photon source, the gather and the camera read.
    const SurfaceLookup& surfaces() const { return *surfaces_; }
    const std::shared_ptr<const SurfaceLookup>& sharedSurfaces() const { return surfaces_; }

private:
    struct Part {
        std::vector<uint32_t> triangles;  // Embree primID -> scene triangle (increasing)
        std::vector<uint32_t> vertices;   // Embree vertex -> scene vertex
        unsigned geomId = RTC_INVALID_GEOMETRY_ID;
        // Its filters' data when some of its triangles let light through (at a fixed address:
        // Embree holds the pointer).
        std::unique_ptr<PassThrough> passThrough;
        bool empty() const { return geomId == RTC_INVALID_GEOMETRY_ID; }
    };
    Part addPart(RTCScene target, const Scene& scene, bool dynamic, RTCBuildQuality quality,
                 const std::shared_ptr<const SurfaceLookup>& lookup);
    void fillVertices(RTCGeometry geom, const Part& part, const Scene& scene);
    static void orientTwoSided(PassThrough& pass, const Scene& scene);
    void boundDynamic(const Scene& scene);
    std::optional<SurfaceHit> intersectPart(const EmbreeScene& embree, const Part& part, const Vec3f& origin,
                                            const Vec3f& direction, float tnear, float tfar, bool blendStops) const;

    const EmbreeDevice& device_;
    std::shared_ptr<const SurfaceLookup> surfaces_;  // what the filters and the panes read
    EmbreeScene staticScene_, dynamicScene_;
    Part static_, dynamic_;
    float rayEpsilon_ = 1e-5f;
    // The dynamic triangles' bounds in the current pose, padded: a ray that misses them cannot
    // meet a dynamic triangle, and skips Embree (most occlusion rays pass far from the movers).
    Bounds3f dynamicBounds_;
    // The animation's bounds grown by their extent: from an origin inside, a hit's rounding is far
    // below the padding of dynamicBounds_, so intersect() may skip the dynamic part by them. A
    // camera farther out asks Embree whatever the bounds say.
    Bounds3f nearScene_;
    // The surfaces that pass a share of the light (panes, BLENDs), padded; everything if one
    // moves: a shadow ray that misses them asks occluded(), an any-hit query, not the closest-hit
    // walk of transmittance() (FlightHelmet's one BLEND lens doubled the direct light's time).
    Bounds3f shareBounds_;
};

}  // namespace qsgi
