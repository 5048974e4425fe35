// Direct light, exact (docs/design.md §5.1): the irradiance D_v that reaches vertex v straight from
// the emitters, with v's normal n_v, distances and cosines measured from v itself and visibility
// by shadow rays from v's start point s_v (VertexStarts: v itself, a float error up):
//   point light   I · cosθ_v / d²   when the segment s_v → light is clear (spot lights only inside
//                 their cone, as their photons are);
//   directional   E · cosθ_v        when the ray from s_v against the light's direction is clear;
//   emissive      (1/S) Σ_i L_e · cosθ_v · cosθ_e / (d² · p(x_i)) over S points x_i, each chosen by
//   triangles     the emitter's power and uniformly on it (p = P(triangle) / area), from v's own
//                 scrambled Sobol points: stratified over the emitters by power, with the cosine
//                 and distance terms exact. Only the front (CCW) side emits, as for photons.
//   environment   a uniform sky: (1/S) Σ π L V(ω_i) over S cosine-distributed directions (π L
//                 exactly where nothing is in the way); a map: S cosine-distributed and S
//                 map-distributed directions, each L cosθ / (p_cos + p_map) / S (balance heuristic),
//                 shadow rays to infinity.
// One ray per punctual light; S for all emissive triangles together; S (sky) or 2S (map) for the
// environment. Each vertex's sum runs in a
// fixed order in one thread, so the bits depend on nothing but the geometry and the seed.
//
// After a move only vertices whose start moved, or one of whose shadow segments meets a mover's old
// or new bounds, can change (a segment that meets neither saw the same geometry before and after):
// raysMeeting() finds them from the segments alone, without tracing, and recompute() gives them
// exactly what computeAll() would. Lights are static (docs/design.md §2): the emitters stay as
// computeAll() read them.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "estimate/vertex_starts.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/work_counter.h"

namespace qsgi {

class DirectLight {
public:
    DirectLight(uint32_t samples, uint64_t seed) : samples_(samples), seed_(seed) {}

    // Every vertex, for the scene's current pose (bvh holds it). Reads the emitters anew. Vertices
    // flagged in `dark` (if given: the dark back sides, FinalGather::darkBackSides) get 0 and cast
    // nothing, as hidden ones.
    void computeAll(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, WorkCounter* progress = nullptr,
                    const std::vector<uint8_t>* dark = nullptr);
    // The given vertices only, with the emitters as computeAll() last read them.
    void recompute(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const std::vector<uint32_t>& vertices,
                   const std::vector<uint8_t>* dark = nullptr);
    // Vertices (increasing) one of whose shadow segments meets one of `boxes`.
    std::vector<uint32_t> raysMeeting(const Scene& scene, const VertexStarts& starts, const std::vector<Bounds3f>& boxes) const;

    const std::vector<Vec3f>& irradiance() const { return irradiance_; }
    // Shadow rays cast by the last computeAll() or recompute().
    uint64_t raysCast() const { return raysCast_; }

private:
    struct Emitter {
        uint32_t triangle;
        Vec3f radiance;  // L_e
        float area;
        double probability;  // of being chosen
        // Its corners and unit normal (Scene::geometricNormal), read once: emitters never move,
        // and a sample then touches no scene array (a refined light panel's thousands of
        // triangles made these reads a fifth of the direct light's time).
        std::array<Vec3d, 3> corner;
        Vec3d normal;
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

    uint32_t samples_;
    uint64_t seed_;
    std::vector<Emitter> emitters_;
    std::vector<double> cdf_;  // emitters_' cumulative probabilities, last = 1
    std::vector<Vec3f> irradiance_;
    uint64_t raysCast_ = 0;
};

}  // namespace qsgi
