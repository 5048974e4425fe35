// Vertex values fitted to the surface (--vertex-fit least-squares; issue 47, docs/method.md "The
// least-squares vertex fit"). What a viewer shows is the bake interpolated linearly across each
// triangle; point sampling takes each vertex's own irradiance, so a vertex that is dark or lit
// alone (a floor vertex just inside a block's foot, a ceiling vertex on a panel's edge) smears over
// all its triangles. The fit chooses instead, per mesh, the vertex values x whose interpolation
// g = Σ x_u φ_u is closest to the irradiance sampled over the surface (Kavan, Bargteil & Sloan,
// "Least Squares Vertex Baking", EGSR 2011):
//
//   minimise  Σ_s w_s (g(s) − E_s)²  +  λ Σ_hinges w_e J_e(x)²  +  δ Σ_u (x_u − p_u)².
//
// The samples s are the vertices of a sampling mesh: the output mesh refined by bisection (its own
// vertices first, then each added one the midpoint of two earlier ones, as refinedFrom records), so
// every sample lies in one output triangle and g(s) is a fixed mix of at most three unknowns. The
// renderer refines near contacts (RenderJob: as --refine-contacts R, R 1.5 % of the animation's
// diagonal), where a linear field over a triangle fails; bisectEveryEdge samples every triangle.
// The sampling mesh is solved by the whole pipeline (start points by the vertices' rule, exact
// direct light, the gather, incremental frames) as any mesh is. w_s is a third of the area of the
// sampling triangles round s (the lumped quadrature of ∫ (g − E)²), and 0 for a sample that is hidden or
// covered (inside or under closed geometry: FinalGather's rule), so the floor under a block's foot
// has no say and its vertices take whatever values make their visible triangles right. A sample
// all of whose output vertices are unseen has no weight either: none of them can carry it (the
// ceiling over a fixture hung a centimetre below, covered at the output's vertices, seen at the
// finer samples between), and weighed it would fix only sums of unseen values. An unknown no
// weighed sample lies on keeps its point value (issue 60).
// J_e is the jump of g's gradient across a hinge — an edge shared by two triangles of the same
// unknowns whose normals are within 45° — with the two triangles unfolded into one plane, w_e the
// hinges' area over 3 times their mean height squared (so that λ weighs a gradient's jump as the
// data weighs a value's error over the same area): the regulariser of Kavan et al., which decides
// what the samples leave free and is 0 for a field linear across the hinge. δ, 10⁻⁶ of the mesh's
// sample weight per unknown, pulls each unknown toward its point value p_u so that every system is positive
// definite (a mesh that is all hidden keeps its point values); for a field linear on the mesh the
// point values are the fit's, so the fit reproduces it exactly.
//
// The unknowns are a mesh's vertices welded by position and normal: copies split for their UVs are
// one unknown (no false seam), those split for their normals, and separate meshes (materials), are
// not. (A file without normals gets each copy its own area-weighted normal, and those differ: there
// UV copies stay apart.) For a skinned mesh a sample's place is where the bisection made it, in
// object space: posed, a midpoint's blended skinning puts it near its output triangle, not on it.
// Each mesh's sparse system is factorised by Eigen's SimplicialLDLT (single-threaded, fill-
// reducing AMD order): the same matrix gives the same bits. A mesh keeps its factorisation while
// its matrix is bitwise the one it was made from (a static mesh whose samples' weights did not
// change) and solves only the new right-hand side; a mesh whose weights changed (a floor under a
// walker's feet) or that moved or deforms is factorised afresh. The result is a pure function of
// the pose and the samples' irradiance, so incremental frames equal --full-recompute's bits.
//
// Fitted values may be negative (an overshoot beside a sharp shadow); they are written as 0.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"

namespace qsgi {

class VertexFit {
public:
    // λ, the regulariser's weight. Measured on data/cornell (docs/method.md): any λ > 0 smooths
    // the light's fall toward a contact on into the hidden floor beyond it, where it overshoots
    // below 0 and is clamped, which lifts the visible side (over the surface 1.86 % at λ = 0,
    // 1.99 % at 0.002, 2.08 % at 0.05; within 5 cm of a contact 20.7, 22.7 and 24.1 %): off by
    // default, the ridge alone deciding what no sample does.
    static constexpr double kSmoothing = 0;
    // δ, relative to a mesh's mean sample weight.
    static constexpr double kRidge = 1e-6;

    // output: the mesh the bake is written on; samples: a copy of it refined by bisection
    // (refineMeshWhere, refineContacts, bisectEveryEdge), in the same pose. smoothing: λ (0: none).
    VertexFit(const Scene& output, const Scene& samples, double smoothing = kSmoothing);
    ~VertexFit();
    VertexFit(VertexFit&&) noexcept;
    VertexFit& operator=(VertexFit&&) noexcept;

    struct Report {
        uint64_t factorisations = 0;    // meshes factorised afresh
        uint64_t clampedVertices = 0;   // output vertices with a negative fitted channel, written as 0
        uint64_t pointFallbacks = 0;    // meshes whose solve failed (not expected) and kept their point values
    };
    // The output's irradiance fitted to the samples' (`sampleIrradiance`, one per sample vertex;
    // unseen[s] != 0: no weight; empty: none unseen beyond the hidden ones), both scenes in the
    // current pose; out's radiosity follows (computeRadiosity). Hidden output vertices are 0, as everywhere.
    Report fit(const Scene& output, const Scene& samples, const std::vector<Vec3f>& sampleIrradiance,
               const std::vector<uint8_t>& unseen, VertexRadiosity& out);

    // Bytes kept across frames (each mesh's matrix and factorisation).
    size_t bytes() const;

private:
    struct Mesh;
    std::vector<std::unique_ptr<Mesh>> meshes_;
    double smoothing_;
};

}  // namespace qsgi
