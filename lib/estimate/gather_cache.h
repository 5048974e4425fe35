// The final gather's irradiance cache over vertices (docs/method.md, "The gather cache"; issue 45):
// full gathers at a subset of vertices, the records, and every other vertex interpolated from the
// records it reaches across its own surface. Dense meshes then pay M rays where the lighting
// changes, not at every vertex.
//
// Where records go: Ward's split sphere. Every vertex casts the first P of its M gather rays (the
// probes); H_v, the harmonic mean of their hit distances (a miss: infinitely far), is how far v is
// from the geometry that shapes its indirect light, and R_v = a·H_v (at most a times the
// animation's diagonal) the spacing its light tolerates, a the tolerance. Space is cut into cubic
// cells at every power-of-two fraction of the animation's diagonal; v asks for a record in the
// coarsest cell whose diagonal is at most R_v, and each (cell, piece of surface, normal's major
// axis) that some vertex asks for gets one: its vertex nearest the cell's centre. So records crowd
// at contacts, in corners and on concave surfaces, and thin out on open ones.
//
// Who reads which record: each record's light spreads along its mesh's edges (a geodesic flood,
// Dijkstra's order) up to its own R (the chosen asker of a cell asked at the cell's level, so it
// reaches the cell's diagonal), only into vertices whose own R is farther than the record, whose
// normal is within 30° of its own, and over edges whose ends see each other; each vertex keeps
// the first K to reach it (Dijkstra's order: nearest first). A vertex no record reaches (across a
// crease, a fold, a gap in its mesh) becomes a record itself, and the flood runs again until every
// vertex is reached. Light never crosses from one welded surface to another (meshes sharing vertex
// positions are one), from one side of a wall or thin partition to the other, or round a sharp
// edge. The weights, ((R − g)/g)² (R
// the smaller of the record's and the vertex's) times how close the normals are, are all but
// infinite at a record: a record's value is its own gather.
//
// Everything is a pure function of the pose and the probes, computed from scratch every frame in a
// fixed order — no hysteresis — so an update reaches exactly the records and weights a full
// recomputation does, for any thread count. a = 0 makes every vertex a record: the per-vertex
// gather's bits.
#pragma once

#include <cstdint>
#include <vector>

#include "estimate/final_gather.h"
#include "estimate/lighting_settings.h"
#include "estimate/vertex_starts.h"
#include "scene/mesh_topology.h"
#include "scene/scene.h"

namespace qsgi {

class GatherCache {
public:
    // The probes every vertex casts (of its M gather rays).
    static constexpr uint32_t kProbeRays = LightingSettings::kGatherProbeRays;
    // Records each vertex reads, at most.
    static constexpr uint32_t kRecordsPerVertex = 4;

    explicit GatherCache(float tolerance) : tolerance_(tolerance) {}

    // Chooses the records and each vertex's weights for the current pose, from the probes `rays`
    // holds (castAll and its updates).
    // bvh: the current pose's, for the edges' visibility.
    void select(const Scene& scene, const SceneBvh& bvh, const VertexStarts& starts, const FinalGather& rays);
    const std::vector<uint8_t>& records() const { return record_; }
    size_t recordCount() const { return recordCount_; }

    // Fills every vertex that is not a record from the records' values in `irradiance`.
    void interpolate(std::vector<Vec3f>& irradiance) const;
    // The cache's answer at a point of a triangle (barycentrics b1, b2 of its corners 1 and 2): the
    // records each corner reads, weighted as at that corner for the distance through it to the
    // point, times the corner's barycentric (at a vertex, its own value; continuous across edges). `irradiance`: every vertex's, as
    // interpolate leaves it. Needs select() for the current pose.
    Vec3f irradianceAt(const Scene& scene, uint32_t triangle, float b1, float b2, const std::vector<Vec3f>& irradiance) const;

    // The records whose values make v's (with a weight above 0; v itself if it is one).
    std::vector<uint32_t> recordsRead(uint32_t v) const;
    // The spacing R_v each vertex asked for (scene units; 0: a record of its own).
    const std::vector<float>& spacing() const { return spacing_; }
    size_t bytes() const;

private:
    struct Label {
        uint32_t record = UINT32_MAX;
        float distance = 0;  // geodesic, along the mesh's edges
    };
    struct Adjacency;
    // Every vertex's labels: the first kRecordsPerVertex records (record_) whose light reaches it.
    void flood(const Adjacency& adjacency, const std::vector<uint32_t>& pieces);
    // Calls visit(record, weight) for each record v's labels name with a weight above 0, nearest
    // first: what v's interpolated value is made of.
    template <typename Visit>
    void forEachRecordRead(uint32_t v, Visit&& visit) const {
        for (uint32_t i = 0; i < kRecordsPerVertex; ++i) {
            const Label& label = labels_[size_t(v) * kRecordsPerVertex + i];
            if (label.record == UINT32_MAX) break;
            const float w = weight(label, normal_[v], spacing_[v]);
            if (w > 0) visit(label.record, double(w));
        }
    }
    // A record's weight at a vertex (or point) with this normal and spacing R.
    float weight(const Label& label, const Vec3f& normal, float spacing) const;

    float tolerance_;
    std::vector<float> spacing_;      // R_v
    std::vector<uint8_t> record_;     // by vertex
    std::vector<float> reach_;        // by vertex (records only)
    std::vector<Vec3f> normal_;       // n_v at the selection, every vertex's
    std::vector<Label> labels_;       // kRecordsPerVertex a vertex, nearest first; record UINT32_MAX: none
    size_t recordCount_ = 0;
};

}  // namespace qsgi
