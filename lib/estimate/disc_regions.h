// What each vertex's disc can receive (docs/design.md §5): its own surface's height band, and which cells
// of its fixed pattern light can reach from v's side. A cell is reachable when the segment from
// the start point s_v = v + ε_v⁺·n_v + min(10⁻³ r, ε)·u_v to the cell's centre lifted by ε_v⁺
// meets no geometry: cells behind an adjacent wall, under a box standing beside v or inside a
// solid are not. A cell whose corners disagree with its centre is *mixed* (a wall runs through
// it): a crossing or impact there is tested on its own with the same kind of segment, and the
// cell's area counts by the reachable share of 4×4 sub-points. So light beyond a thin partition
// never counts, however the partition cuts the pattern (deciding a cell by its centre alone would let a cell
// that straddles the partition count the far side's light). For the photon map a cell is also *covered*: reachable, and a probe from its
// lifted centre along −n_v first meets a surface facing n_v (within 45°) inside [−ε_v⁻, ε_v⁺]
// — a photon map has impacts only where there is such a surface.
//
// Static vertices are computed once; per frame only the vertices whose test region (the
// cylinder of radius r, |height| ≤ r, around v) a moved object's old or new bounds touch, and
// the moved vertices themselves, are recomputed — with the same function, so the result equals a
// from-scratch computation of that frame.
#pragma once

#include <bitset>
#include <cstdint>
#include <vector>

#include "estimate/disc_pattern.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/work_counter.h"

namespace qsgi {

struct VertexDisc {
    Vec3f tangent{0.0f}, bitangent{0.0f};  // discFrame(n_v)
    Vec3f start{0.0f};                       // s_v
    float epsAbove = 0, epsBelow = 0;        // ε_v⁺, ε_v⁻ (own surface; ε_v⁻ only with coverage, else 0)
    CellMask reachable;                      // DETP `clip` / `linear`: reachable, centre and corners
    CellMask mixed;                          // corners disagree: decide per point
    CellMask covered;                        // photon map (only with coverage): reachable or mixed,
                                             // and over a surface facing n_v
    // Reachable share (of 16 sub-points) of each mixed cell, in cell order.
    std::vector<std::pair<uint8_t, uint8_t>> mixedShare;
    float reachableArea = 0;  // reachable share of the disc: (cells + mixed shares) / kDiscCells
    bool fallback = false;    // empty own surface: the estimators use the `paper` rule here

    bool operator==(const VertexDisc& o) const;
    // Share (0…1) of a cell that is reachable.
    double cellShare(int cell) const;
    // Photon map: area (units of r²) of the disc of radius s·r that covered cells span.
    double coveredArea(double s) const;
};

// Whether light reaches a point of v's disc, as far as its cell tells: yes, no, or (a mixed
// cell) only the point's own segment can say.
enum class Reach { No, Yes, TestPoint };
inline Reach reachInCell(const VertexDisc& disc, int cell) {
    if (disc.reachable.test(cell)) return Reach::Yes;
    return disc.mixed.test(cell) ? Reach::TestPoint : Reach::No;
}

// Whether the point (x, y) of v's disc (units of r), lifted by ε_v⁺, is reachable from s_v.
bool discPointReachable(const VertexDisc& disc, const Vec3f& centre, const Vec3f& normal, float radius, double x,
                        double y, const SceneBvh& bvh);

// The decision for a point whose cell gave `reach`: TestPoint is settled by its own segment
// (no bvh: not reachable). Every estimator decides through here, so they agree to the bit.
bool pointReachable(Reach reach, const VertexDisc& disc, const Vec3f& centre, const Vec3f& normal, float radius,
                    double x, double y, const SceneBvh* bvh);

class DiscRegions {
public:
    // radius: the disc radius r. withCoverage: also find the photon map's covered cells.
    DiscRegions(float radius, bool withCoverage) : radius_(radius), withCoverage_(withCoverage) {}
    // Every vertex, for the scene's current pose (bvh must hold that pose).
    // progress, if given, counts the vertices done.
    void computeAll(const Scene& scene, const SceneBvh& bvh, WorkCounter* progress = nullptr);
    // The given vertices only (sorted or not); the rest keep their values. Returns those of them
    // whose disc may now decide a crossing differently: its disc changed, or it has mixed cells
    // (decided point by point against the current geometry). The others count every segment
    // exactly as before.
    std::vector<uint32_t> recompute(const Scene& scene, const SceneBvh& bvh, const std::vector<uint32_t>& vertices,
                                    WorkCounter* progress = nullptr);
    // Vertices to recompute after a move: those whose test region overlaps one of `movedBounds`
    // (old and new bounds of each moved object), and those flagged in `vertexMoved`.
    std::vector<uint32_t> touchedBy(const Scene& scene, const std::vector<Bounds3f>& movedBounds,
                                    const std::vector<uint8_t>& vertexMoved) const;

    const VertexDisc& operator[](size_t v) const { return discs_[v]; }
    size_t size() const { return discs_.size(); }
    float radius() const { return radius_; }
    bool hasCoverage() const { return withCoverage_; }
    // Vertices with an empty own surface (paper fallback), and vertices with no reachable cell
    // (buried in geometry: E = 0). Both are reported in timing.json.
    uint64_t fallbackVertices() const;
    uint64_t buriedVertices() const;
    uint64_t mixedCells() const;  // cells cut by geometry, over all vertices
    // What the last computeAll or recompute asked Embree: its rays against the static geometry
    // or the whole scene (corners, centres, sub-points, coverage probes, start searches; not the
    // dynamic halves, which the movers' bounds clip away first almost always), and the vertices
    // whose static rays were skipped (no static triangle near rises to their height, design.md §5).
    // And the vertices whose ε_v⁺ OwnSurfaceTree proved without walking their own surface.
    struct Work {
        uint64_t rays = 0;
        uint64_t staticRaysSkipped = 0;
        uint64_t ownSurfacesProved = 0;
        Work& operator+=(const Work& o) {
            rays += o.rays;
            staticRaysSkipped += o.staticRaysSkipped;
            ownSurfacesProved += o.ownSurfacesProved;
            return *this;
        }
    };
    const Work& lastWork() const { return lastWork_; }
    // Off: every static ray is traced, the shortcut never taken (the reference its tests compare with).
    void useStaticShortcut(bool on) { staticShortcut_ = on; }
    // Off: every own surface is walked whole, OwnSurfaceTree never asked (the same reference).
    void useOwnSurfaceShortcut(bool on) { ownSurfaceShortcut_ = on; }
    // OwnSurfaceTree is built where it pays (dense meshes, many vertices); tests build it always
    // or never, so that its answers are compared with the walk's and the point query's on any scene.
    enum class TreeUse { Never, WhereItPays, Always };
    void setTreeUse(TreeUse use) { treeUse_ = use; }
    // Bytes of the static answers kept for recomputed vertices.
    size_t keptAnswerBytes() const { return answers_.capacity() * sizeof(StaticAnswers) + answerSlot_.capacity() * sizeof(int32_t); }

    // What the static BVH answered for a vertex's corner and cell-centre rays. occluded() is the
    // static answer or the dynamic one; the static scene never changes, so a static vertex whose
    // rays are the same (start and lift) gets the same static answers every frame, and a
    // recompute asks only the dynamic BVH — exactly what a from-scratch computation would find.
    // Kept from a vertex's first recompute on.
    struct StaticAnswers {
        bool valid = false;
        Vec3f start{0.0f};
        float epsAbove = 0;
        std::bitset<size_t(2 * kDiscCells)> clear;  // corners of rings 1…16, then cell centres
    };

private:
    std::vector<uint32_t> compute(const Scene& scene, const SceneBvh& bvh, const std::vector<uint32_t>& vertices, bool keepAnswers,
                                  WorkCounter* progress);

    float radius_;
    bool withCoverage_;
    std::vector<VertexDisc> discs_;
    std::vector<int32_t> answerSlot_;  // per vertex, into answers_ (−1: none kept)
    std::vector<StaticAnswers> answers_;
    Work lastWork_;
    bool staticShortcut_ = true;
    bool ownSurfaceShortcut_ = true;
    TreeUse treeUse_ = TreeUse::WhereItPays;
};

}  // namespace qsgi
