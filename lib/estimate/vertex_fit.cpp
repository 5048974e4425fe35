#include "estimate/vertex_fit.h"

#include "estimate/own_surface.h"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <stdexcept>
#include <tuple>

namespace qsgi {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

Vec3d at(const Scene& scene, uint32_t v) { return Vec3d(scene.positions[v]); }

// A sample's place on the output mesh: Σ weight[k] · vertex[k] (count of them used).
struct SamplePlace {
    uint32_t vertex[3] = {0, 0, 0};
    double weight[3] = {0, 0, 0};
    int count = 0;
    void add(uint32_t v, double w) {
        for (int k = 0; k < count; ++k)
            if (vertex[k] == v) {
                weight[k] += w;
                return;
            }
        // Every sampling triangle lies in one output triangle, so a midpoint's two ends name at most three vertices.
        if (count == 3) throw std::logic_error("VertexFit: a sample lies between more than three output vertices");
        vertex[count] = v, weight[count] = w, ++count;
    }
};

bool sameBits(const SparseMatrix& a, const SparseMatrix& b) {
    if (a.rows() != b.rows() || a.nonZeros() != b.nonZeros()) return false;
    const size_t nnz = size_t(a.nonZeros());
    return std::memcmp(a.outerIndexPtr(), b.outerIndexPtr(), sizeof(int) * size_t(a.outerSize() + 1)) == 0 &&
           std::memcmp(a.innerIndexPtr(), b.innerIndexPtr(), sizeof(int) * nnz) == 0 &&
           std::memcmp(a.valuePtr(), b.valuePtr(), sizeof(double) * nnz) == 0;
}

}  // namespace

struct VertexFit::Mesh {
    uint32_t firstOutput = 0, outputCount = 0;    // the output scene's vertices of this mesh
    uint32_t firstSample = 0, sampleCount = 0;    // the sampling scene's
    uint32_t firstSampleTriangle = 0, sampleTriangleCount = 0;
    uint32_t unknowns = 0;
    std::vector<uint32_t> unknownOf;               // by output vertex (local)
    // By sample vertex (local): where it lies on the output mesh, as up to three output vertices
    // (local) and their barycentric weights (an output vertex: itself, weight 1).
    std::vector<SamplePlace> place;
    // Hinges: output vertices (local) a, b of the shared edge, c and d opposite it.
    std::vector<std::array<uint32_t, 4>> hinges;

    SparseMatrix matrix;  // the one `factor` was made from
    Eigen::SimplicialLDLT<SparseMatrix> factor;
    bool factored = false;
};

VertexFit::VertexFit(const Scene& output, const Scene& samples, double smoothing) : smoothing_(smoothing) {
    if (output.instances.size() != samples.instances.size())
        throw std::logic_error("VertexFit: the sampling mesh is not the output's refined");
    for (size_t i = 0; i < output.instances.size(); ++i) {
        const MeshInstance& o = output.instances[i];
        const MeshInstance& s = samples.instances[i];
        // Its own vertices first, as they are; then the added ones, each in refinedFrom.
        if (s.vertexCount < o.vertexCount || s.refinedFrom.size() != o.refinedFrom.size() + (s.vertexCount - o.vertexCount) ||
            !std::equal(o.objectPositions.begin(), o.objectPositions.end(), s.objectPositions.begin()))
            throw std::logic_error("VertexFit: the sampling mesh is not the output's refined");
        const size_t added = s.vertexCount - o.vertexCount;
        auto mesh = std::make_unique<Mesh>();
        mesh->firstOutput = o.firstVertex;
        mesh->outputCount = o.vertexCount;
        mesh->firstSample = s.firstVertex;
        mesh->sampleCount = s.vertexCount;
        mesh->firstSampleTriangle = s.firstTriangle;
        mesh->sampleTriangleCount = s.triangleCount;

        // Unknowns: vertices welded by object-space position and world normal (the normal the
        // render shades with), in order of first appearance.
        std::map<std::tuple<float, float, float, float, float, float>, uint32_t> welded;
        mesh->unknownOf.resize(o.vertexCount);
        for (uint32_t v = 0; v < o.vertexCount; ++v) {
            const Vec3f p = o.objectPositions[v], n = output.normals[o.firstVertex + v];
            const auto [it, isNew] = welded.emplace(std::make_tuple(p.x, p.y, p.z, n.x, n.y, n.z), mesh->unknowns);
            if (isNew) ++mesh->unknowns;
            mesh->unknownOf[v] = it->second;
        }
        // An added vertex is the midpoint of two earlier ones: half of each one's place.
        mesh->place.resize(s.vertexCount);
        for (uint32_t v = 0; v < o.vertexCount; ++v) mesh->place[v].add(v, 1.0);
        for (size_t j = 0; j < added; ++j) {
            const auto [a, b] = s.refinedFrom[o.refinedFrom.size() + j];
            if (a >= o.vertexCount + j || b >= o.vertexCount + j)
                throw std::logic_error("VertexFit: a sample is not the midpoint of two earlier vertices");
            SamplePlace& p = mesh->place[o.vertexCount + j];
            for (const uint32_t end : {a, b})
                for (int k = 0; k < mesh->place[end].count; ++k) p.add(mesh->place[end].vertex[k], 0.5 * mesh->place[end].weight[k]);
        }

        // Hinges, decided on the pose the fit is made in (the rest pose): edges of two triangles,
        // by their unknowns, whose normals are within 45°.
        std::map<std::pair<uint32_t, uint32_t>, std::vector<std::array<uint32_t, 3>>> edges;
        for (uint32_t t = 0; t < o.triangleCount; ++t) {
            const Triangle& tri = output.triangles[o.firstTriangle + t];
            for (int e = 0; e < 3; ++e) {
                const uint32_t a = tri.v[e] - o.firstVertex, b = tri.v[(e + 1) % 3] - o.firstVertex,
                               c = tri.v[(e + 2) % 3] - o.firstVertex;
                const uint32_t ua = mesh->unknownOf[a], ub = mesh->unknownOf[b];
                if (ua == ub) continue;
                edges[{std::min(ua, ub), std::max(ua, ub)}].push_back({a, b, c});
            }
        }
        auto normalOf = [&](uint32_t a, uint32_t b, uint32_t c) {
            const Vec3d n = cross(at(output, o.firstVertex + b) - at(output, o.firstVertex + a),
                                  at(output, o.firstVertex + c) - at(output, o.firstVertex + a));
            const double len = length(n);
            return len > 0 ? n / len : Vec3d(0.0);
        };
        for (const auto& [key, sides] : edges) {
            if (sides.size() != 2) continue;
            const auto& [a, b, c] = sides[0];
            const uint32_t d = sides[1][2];
            if (mesh->unknownOf[c] == mesh->unknownOf[d]) continue;  // a fold onto itself
            if (dot(normalOf(a, b, c), normalOf(sides[1][0], sides[1][1], d)) < double(kOwnSurfaceCos)) continue;
            mesh->hinges.push_back({a, b, c, d});
        }
        meshes_.push_back(std::move(mesh));
    }
}

VertexFit::~VertexFit() = default;
VertexFit::VertexFit(VertexFit&&) noexcept = default;
VertexFit& VertexFit::operator=(VertexFit&&) noexcept = default;

VertexFit::Report VertexFit::fit(const Scene& output, const Scene& samples, const std::vector<Vec3f>& sampleIrradiance,
                                 const std::vector<uint8_t>& unseen, VertexRadiosity& out) {
    if (!unseen.empty() && unseen.size() != samples.vertexCount())
        throw std::logic_error("VertexFit: the unseen flags are not the sampling mesh's");
    out.irradiance.assign(output.vertexCount(), Vec3f(0.0f));
    std::vector<Report> reports(meshes_.size());
    tbb::parallel_for(size_t(0), meshes_.size(), [&](size_t i) {
        Mesh& mesh = *meshes_[i];
        Report& report = reports[i];
        // The samples' weights: a third of the area of each sampling triangle round them.
        std::vector<double> weight(mesh.sampleCount, 0.0);
        for (uint32_t t = mesh.firstSampleTriangle; t < mesh.firstSampleTriangle + mesh.sampleTriangleCount; ++t) {
            const double third = double(samples.triangleArea(t)) / 3;
            for (uint32_t v : samples.triangles[t].v) weight[v - mesh.firstSample] += third;
        }
        for (uint32_t s = 0; s < mesh.sampleCount; ++s) {
            const uint32_t g = mesh.firstSample + s;
            if ((!unseen.empty() && unseen[g]) || samples.vertexHidden[g]) weight[s] = 0;
        }
        // A sample between output vertices that are all unseen themselves (the samples are the
        // output's own vertices first) has no vertex to carry it: the ceiling over a panel hung a
        // centimetre below it, where the sampling mesh's finer triangles resolve the gap that the
        // output's do not, so its midpoints are seen and its vertices covered. Weighed, those
        // samples fix only sums of unseen values (a chequerboard of the grid's two halves is left
        // free), and the solve swings the unknowns about. Unweighed, such a vertex has no sample
        // and keeps its own value; a covered vertex beside a seen one (a floor vertex just inside
        // a block's foot) still takes the seen part of its triangles from the samples there.
        std::vector<uint8_t> outputSeen(mesh.outputCount);
        for (uint32_t v = 0; v < mesh.outputCount; ++v) outputSeen[v] = weight[v] > 0;
        for (uint32_t s = mesh.outputCount; s < mesh.sampleCount; ++s) {
            const SamplePlace& p = mesh.place[s];
            bool carried = false;
            for (int k = 0; k < p.count; ++k) carried = carried || outputSeen[p.vertex[k]];
            if (!carried) weight[s] = 0;
        }
        double total = 0;
        for (uint32_t s = 0; s < mesh.sampleCount; ++s) total += weight[s];

        // Point values: each unknown's mean over its vertices' own samples.
        Eigen::MatrixX3d point = Eigen::MatrixX3d::Zero(mesh.unknowns, 3);
        std::vector<uint32_t> copies(mesh.unknowns, 0);
        for (uint32_t v = 0; v < mesh.outputCount; ++v) {
            const Vec3f& e = sampleIrradiance[mesh.firstSample + v];
            point.row(mesh.unknownOf[v]) += Eigen::RowVector3d(e.x, e.y, e.z);
            ++copies[mesh.unknownOf[v]];
        }
        for (uint32_t u = 0; u < mesh.unknowns; ++u) point.row(u) /= double(copies[u]);

        Eigen::MatrixX3d x = point;
        if (total > 0) {
            std::vector<Eigen::Triplet<double>> entries;
            Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(mesh.unknowns, 3);
            for (uint32_t s = 0; s < mesh.sampleCount; ++s) {
                if (weight[s] == 0) continue;
                const SamplePlace& p = mesh.place[s];
                const Vec3f& e = sampleIrradiance[mesh.firstSample + s];
                const Eigen::RowVector3d value(e.x, e.y, e.z);
                for (int r = 0; r < p.count; ++r) {
                    const uint32_t ur = mesh.unknownOf[p.vertex[r]];
                    for (int q = 0; q < p.count; ++q)
                        entries.emplace_back(ur, mesh.unknownOf[p.vertex[q]], weight[s] * p.weight[r] * p.weight[q]);
                    rhs.row(ur) += (weight[s] * p.weight[r]) * value;
                }
            }
            // The regulariser: the jump across each hinge of g's derivative away from the edge, in
            // the plane the two triangles unfold into (0 when g is linear across the hinge).
            if (smoothing_ > 0)
                for (const auto& [a, b, c, d] : mesh.hinges) {
                    const Vec3d pa = at(output, mesh.firstOutput + a), pb = at(output, mesh.firstOutput + b);
                    const Vec3d edge = pb - pa;
                    const double len2 = dot(edge, edge);
                    if (!(len2 > 0)) continue;
                    // Of an opposite corner: where its foot falls along the edge (0 at a, 1 at b) and its height.
                    auto foot = [&](uint32_t corner, double& along, double& height) {
                        const Vec3d q = at(output, mesh.firstOutput + corner) - pa;
                        along = dot(q, edge) / len2;
                        height = length(q - along * edge);
                    };
                    double alongC, heightC, alongD, heightD;
                    foot(c, alongC, heightC);
                    foot(d, alongD, heightD);
                    const double len = std::sqrt(len2);
                    if (!(heightC > 1e-6 * len && heightD > 1e-6 * len)) continue;
                    const uint32_t u[4] = {mesh.unknownOf[a], mesh.unknownOf[b], mesh.unknownOf[c], mesh.unknownOf[d]};
                    const double k[4] = {-(1 - alongC) / heightC - (1 - alongD) / heightD, -alongC / heightC - alongD / heightD,
                                         1 / heightC, 1 / heightD};
                    const double areas = 0.5 * len * (heightC + heightD);
                    const double mean = 0.5 * (heightC + heightD);
                    const double w = smoothing_ * areas / 3 * mean * mean;
                    for (int r = 0; r < 4; ++r)
                        for (int q = 0; q < 4; ++q) entries.emplace_back(u[r], u[q], w * k[r] * k[q]);
                }
            const double ridge = kRidge * total / double(mesh.unknowns);
            for (uint32_t u = 0; u < mesh.unknowns; ++u) {
                entries.emplace_back(u, u, ridge);
                rhs.row(u) += ridge * point.row(u);
            }
            SparseMatrix matrix(mesh.unknowns, mesh.unknowns);
            matrix.setFromTriplets(entries.begin(), entries.end());
            if (!mesh.factored || !sameBits(matrix, mesh.matrix)) {
                mesh.matrix = std::move(matrix);
                mesh.factor.compute(mesh.matrix);
                mesh.factored = mesh.factor.info() == Eigen::Success;
                ++report.factorisations;
            }
            // A factorisation that fails or a solve that is not finite (neither is expected of a
            // positive definite system) leaves the point values, counted.
            bool solved = false;
            if (mesh.factored) {
                const Eigen::MatrixX3d fitted = mesh.factor.solve(rhs);
                if (fitted.allFinite()) x = fitted, solved = true;
            }
            if (!solved) ++report.pointFallbacks;
            // An unknown no weighed sample lies on keeps its point value, to the bit. With λ = 0
            // its row is the ridge's alone, so the solve gives that value to rounding; with λ > 0
            // the hinges continue the seen field into it (TheRegulariserContinues…) instead.
            if (smoothing_ == 0) {
                std::vector<uint8_t> weighed(mesh.unknowns, 0);
                for (uint32_t s = 0; s < mesh.sampleCount; ++s)
                    if (weight[s] > 0)
                        for (int k = 0; k < mesh.place[s].count; ++k) weighed[mesh.unknownOf[mesh.place[s].vertex[k]]] = 1;
                for (uint32_t u = 0; u < mesh.unknowns; ++u)
                    if (!weighed[u]) x.row(u) = point.row(u);
            }
        }
        for (uint32_t v = 0; v < mesh.outputCount; ++v) {
            const uint32_t g = mesh.firstOutput + v;
            if (output.vertexHidden[g]) continue;
            const auto row = x.row(mesh.unknownOf[v]);
            if (row.minCoeff() < 0) ++report.clampedVertices;
            out.irradiance[g] = Vec3f(float(std::max(0.0, row(0))), float(std::max(0.0, row(1))), float(std::max(0.0, row(2))));
        }
    });
    Report total;
    for (const Report& r : reports) {
        total.factorisations += r.factorisations;
        total.clampedVertices += r.clampedVertices;
        total.pointFallbacks += r.pointFallbacks;
    }
    computeRadiosity(output, out);
    return total;
}

size_t VertexFit::bytes() const {
    size_t bytes = 0;
    for (const std::unique_ptr<Mesh>& mesh : meshes_) {
        bytes += sizeof(Mesh) + mesh->unknownOf.capacity() * sizeof(uint32_t) +
                 mesh->place.capacity() * sizeof(SamplePlace) + mesh->hinges.capacity() * sizeof(mesh->hinges[0]);
        bytes += size_t(mesh->matrix.nonZeros()) * (sizeof(double) + sizeof(int)) * 2;  // the matrix and about its factor
    }
    return bytes;
}

}  // namespace qsgi
