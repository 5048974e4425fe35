// Direct light, exact (docs/design.md §5.1): the irradiance D_v that reaches vertex v straight from
// the emitters, with v's normal n_v, distances and cosines measured from v itself and visibility
// by shadow rays from v's start point s_v (VertexStarts: v itself, a float error up):
//   point light   I · cosθ_v / d²   when the segment s_v → light is clear (spot lights only inside
//                 their cone, as their photons are);
//   directional   E · cosθ_v        when the ray from s_v against the light's direction is clear;
//   emissive      (1/S) Σ_i L_e · cosθ_v · cosθ_e / (d² · p(x_i)) over S points x_i, each chosen
//   triangles     through the light tree (light_tree.h) by what its emitters can send to v, and
//                 uniformly on the chosen triangle (p = P(triangle at v) / area), from v's own
//                 scrambled Sobol points: stratified over the emitters, with the cosine and
//                 distance terms exact. Only the front (CCW) side emits, as for photons.
//   environment   a uniform sky: (1/S) Σ π L V(ω_i) over S cosine-distributed directions (π L
//                 exactly where nothing is in the way); a map: S cosine-distributed and S
//                 map-distributed directions, each L cosθ / (p_cos + p_map) / S (balance heuristic),
//                 shadow rays to infinity.
// One ray per punctual light while there are at most S point and spot lights (exact, and no more
// rays than sampling them would cast); past S, point and spot lights join the emissive triangles
// in the tree and share their S samples, each I cosθ_v / (d² P(light at v)) — a thousand lamps
// then cost S rays a vertex, not a thousand. Directional lights likewise: exact up to S of them,
// past S S samples of their own, each chosen by its irradiance E. S (sky) or 2S
// (map) rays for the environment. Each vertex's sum runs in a fixed order in one thread, so the
// bits depend on nothing but the geometry and the seed.
//
// After a move only vertices whose start moved, or one of whose shadow segments meets a mover's old
// or new bounds, can change (a segment that meets neither saw the same geometry before and after):
// raysMeeting() finds them from the segments alone, without tracing, and recompute() gives them
// exactly what computeAll() would. Making a vertex's segments again (the tree's descent, its Sobol
// points) cost as much as its shadow rays; so raysMeeting first rules out, by cones from the start
// down the light tree (as the gather's update rules out kept rays), every vertex no segment of
// which can reach a box (issue 60: a later frame's direct light 3.2× faster on data/cornell's
// flying block, 0.031 s against 0.098, the same rays cast). Lights are static (docs/design.md §2): the emitters and their
// tree are read once, by the first computeAll().
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "estimate/vertex_starts.h"
#include "scene/scene.h"
#include "trace/light_tree.h"
#include "trace/scene_bvh.h"
#include "util/work_counter.h"

namespace qsgi {

class DirectLight {
public:
    DirectLight(uint32_t samples, uint64_t seed) : samples_(samples), seed_(seed) {}

    // Every vertex, for the scene's current pose (bvh holds it). Reads the emitters the first time. Vertices
    // flagged in `dark` (if given: the dark back sides, FinalGather::darkBackSides) get 0 and cast
    // nothing, as hidden ones.
    void computeAll(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress = nullptr,
                    const std::vector<uint8_t>* dark = nullptr);
    // The given vertices only, with the emitters as computeAll() last read them.
    void recompute(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint32_t>& vertices,
                   const std::vector<uint8_t>* dark = nullptr);
    // Vertices (increasing) one of whose shadow segments meets one of `boxes`. ByCone first rules
    // out, without making its rays, each vertex whose rays all stay in a region no box's ball
    // meets (the cone from its start that holds the lights, the directional lights' half-lines,
    // the half-space above it toward an environment), as the gather's update does; None makes
    // every vertex's rays (the tests' brute force). `derived`: the vertices whose rays were made.
    enum class ShadowCull { ByCone, None };
    std::vector<uint32_t> raysMeeting(const Scene& scene, const VertexStarts& starts, const std::vector<Bounds3f>& boxes,
                                      ShadowCull cull = ShadowCull::ByCone, uint64_t* derived = nullptr) const;

    const std::vector<Vec3f>& irradiance() const { return irradiance_; }
    // Shadow rays cast by the last computeAll() or recompute().
    uint64_t raysCast() const { return raysCast_; }
    // The emitters sampled through the tree (emissive triangles or their pieces, and the point and
    // spot lights past S), the tree's bytes and the seconds its build took.
    size_t sampledEmitters() const { return emitters_.size(); }
    size_t treeBytes() const { return tree_.bytes() + emitters_.capacity() * sizeof(Emitter); }
    double treeSeconds() const { return treeSeconds_; }
    bool lightsSampled() const { return lightsSampled_; }
    // Whether point and spot lights are sampled through the tree (more of them than S) rather than
    // each given a ray.
    static bool samplesLights(size_t pointAndSpotLights, uint32_t samples) { return samples > 0 && pointAndSpotLights > samples; }

private:
    // An emissive triangle (or a piece of one) or, past S, a point or spot light.
    struct Emitter {
        enum class Kind : uint8_t { Triangle, Point, Spot } kind;
        Vec3f radiance;  // a triangle's L_e, a light's intensity I
        float area;      // a triangle's; 0 for a light
        // A triangle's corners and unit normal (Scene::geometricNormal), read once: emitters never
        // move, and a sample then touches no scene array (a refined light panel's thousands of
        // triangles made these reads a fifth of the direct light's time). A light's position is
        // corner[0], a spot light's direction `normal` and its cos outer cone `cosOuter`.
        std::array<Vec3d, 3> corner;
        Vec3d normal;
        double cosOuter = -1;
    };
    void readEmitters(const Scene& scene);
    // Calls visit(direction, tfar, irradianceIfClear) for each shadow ray of vertex v: the segment
    // from starts.point(v) (direction unit; tfar infinite toward a directional light) and what it
    // brings v if clear. Rays that could carry nothing (the emitter behind v or v behind the
    // emitter) are not visited.
    template <class Visit>
    void forEachShadowRay(const Scene& scene, const VertexStarts& starts, uint32_t v, Visit&& visit) const;
    // forEachShadowRay's rays toward the environment, for vertex v with normal n.
    template <class Visit>
    void environmentRays(const EnvironmentLight& environment, const Vec3d& n, uint32_t v, Visit&& visit) const;
    // Adds the shadow rays it casts to `rays`.
    Vec3f vertexIrradiance(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, uint32_t v, uint64_t& rays) const;

    // raysMeeting's cull (readEmitters sets what it reads): may a shadow ray of the vertex at p
    // (normal n), leaving `start`, meet the ball `box`?
    struct Ball {
        Vec3d centre{0.0};
        double radius = 0;
    };
    // `stack`: the tree descent's, reused by the caller across vertices (this runs for every
    // vertex of every later frame).
    bool mayMeet(const Vec3d& start, const Vec3d& p, const Vec3d& n, const Ball& box, std::vector<uint32_t>& stack) const;

    uint32_t samples_;
    uint64_t seed_;
    std::vector<Vec3d> towardDirectional_;  // each directional light's ray direction
    std::vector<Vec3d> ownRayLights_;       // the point and spot lights with a ray each
    double reachScale_ = 1;                 // the largest coordinate a shadow ray ends at (finite)
    bool environmentRays_ = false;
    std::vector<Emitter> emitters_;
    LightTree tree_;  // over emitters_
    bool emittersRead_ = false;
    bool lightsSampled_ = false;  // point and spot lights are in the tree, not given a ray each
    // Past S directional lights: their indices and the cumulative luminance of their irradiance
    // (empty while each has its ray).
    std::vector<uint32_t> directional_;
    std::vector<double> directionalCdf_;
    double treeSeconds_ = 0;
    std::vector<Vec3f> irradiance_;
    uint64_t raysCast_ = 0;
};

}  // namespace qsgi
