#include "estimate/vertex_starts.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "scene/mesh_topology.h"

namespace qsgi {

namespace {

// δ_v is 2⁻¹⁸ of the larger of v's largest coordinate and its longest incident edge, over the
// least cosine between n_v and an incident face's normal (at least 1/8). Embree decides a hit on
// one of v's own triangles from the start's height above its plane, computed with an error of a
// few float ulps (2⁻²⁴) of those lengths, and the start itself is rounded to float by half an ulp
// of v's coordinates: the height δ_v·cosθ is 64 times that, so a ray leaving above v's surface
// never hits it by rounding, and one entering it always does. It is 4 µm on a 1 m asset.
constexpr double kOffsetScale = 1.0 / 262144.0;
constexpr double kLeastCosine = 0.125;
// The inside test's probes reach 4 δ_v from a start; a start whose probes meet a surface nearer
// than δ_v / 4 lies on it (rounding decides its side).
constexpr double kProbeOffsets = 4, kOnSurfaceOffsets = 0.25;
constexpr double kBorderStepOffsets = 16;

// v's own triangles (those at its welded position), which the probes below look past: stepping a
// hair sideways in a concave crease crosses v's own surface, which is not other geometry.
struct OwnTriangles {
    const uint32_t *begin, *end;
    bool contain(uint32_t tri) const { return std::binary_search(begin, end, tri); }
};

// What short probes from a start find: whether it lies inside closed geometry (a probe first
// meets a back face) and how far the nearest surface around it is. A probe that first meets one
// of v's own triangles tells nothing.
struct StartProbe {
    bool inside = false;
    double clearance = 0;
};

StartProbe probeAround(const Vec3f& start, const Vec3f directions[5], double offset, const SceneBvh& bvh,
                       const std::vector<Vec3f>& frontNormals, const OwnTriangles& own) {
    StartProbe probe;
    const float reach = float(kProbeOffsets * offset);
    probe.clearance = reach;
    for (int k = 0; k < 5; ++k) {
        const auto hit = bvh.intersect(start, directions[k], 0.0f, reach);
        if (!hit || own.contain(hit->triangle)) continue;
        probe.clearance = std::min(probe.clearance, double(hit->t));
        if (dot(frontNormals[hit->triangle], directions[k]) > 0) probe.inside = true;
    }
    return probe;
}

// The edges at a vertex, by the welded id of their other end, each with the count of triangles
// using it: one that a single triangle uses is a border. A fan of more edges than it holds (a
// pole) is taken as no border.
class EdgeCounts {
public:
    void add(uint32_t other) {
        for (int i = 0; i < size_; ++i)
            if (other_[i] == other) {
                ++count_[i];
                return;
            }
        if (size_ == kMost) {
            overflow_ = true;
            return;
        }
        other_[size_] = other;
        count_[size_++] = 1;
    }
    bool border() const {
        if (overflow_) return false;
        for (int i = 0; i < size_; ++i)
            if (count_[i] == 1) return true;
        return false;
    }

private:
    static constexpr int kMost = 64;
    uint32_t other_[kMost];
    int count_[kMost];
    int size_ = 0;
    bool overflow_ = false;
};

bool acceptable(const StartProbe& probe, double offset) { return !probe.inside && probe.clearance >= kOnSurfaceOffsets * offset; }

}  // namespace

double longestIncidentEdge(const Scene& scene, const MeshTopology& topology, uint32_t v) {
    const Vec3d p(scene.positions[v]);
    double longest = 0;
    for (const uint32_t* it = topology.trianglesBegin(v); it != topology.trianglesEnd(v); ++it)
        for (uint32_t c : scene.triangles[*it].v) longest = std::max(longest, length(Vec3d(scene.positions[c]) - p));
    return longest;
}

VertexStart vertexRayStart(const Scene& scene, const SceneBvh& bvh, const MeshTopology& topology,
                           const std::vector<Vec3f>& frontNormals, uint32_t v) {
    VertexStart out;
    const Vec3d p(scene.positions[v]);
    const Vec3d n(scene.normals[v]);
    // v's incident triangles (welded: a UV seam does not cut them): their size, their tilt from
    // n_v, and those that stand up from v's tangent plane (cosine below kLeastCosine: the wall at
    // a floor vertex's foot, where the floor and the wall meet with split normals), which the lift
    // along n_v alone would not clear.
    const double longest = longestIncidentEdge(scene, topology, v);
    double leastCosine = 1, facingArea = 0;
    Vec3d awayFromWalls(0.0), facingCentroid(0.0);
    const Vec3d unit = normalize(n);
    const uint32_t self = topology.weldedId(v);
    EdgeCounts edges;
    for (const uint32_t* it = topology.trianglesBegin(v); it != topology.trianglesEnd(v); ++it) {
        Vec3d centroid(0.0);
        for (uint32_t c : scene.triangles[*it].v) {
            centroid += Vec3d(scene.positions[c]) / 3.0;
            if (topology.weldedId(c) != self) edges.add(topology.weldedId(c));
        }
        const double area = scene.triangleArea(*it);
        if (!(area > 0)) continue;
        const Vec3d face(frontNormals[*it]);
        const double cosine = dot(face, n);
        leastCosine = std::min(leastCosine, cosine);
        // A wall rises on n_v's side of v (a room's wall at its floor's vertex); a face that drops
        // behind it (a box's bottom at a vertex of its side) is no wall to step off.
        if (cosine < kLeastCosine && dot(centroid - p, n) > 0) awayFromWalls += face - unit * dot(face, unit);
        if (cosine > 0) {
            facingCentroid += centroid * area;
            facingArea += area;
        }
    }
    const double magnitude = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z), longest});
    double offset = magnitude * kOffsetScale / std::max(leastCosine, kLeastCosine);
    if (!(offset > 0)) offset = double(scene.sceneEpsilon());  // a lone vertex at the origin
    out.offset = float(offset);
    // A sampling mesh judges a gap by the resolution of the mesh it samples (Scene::coverEdges).
    out.coverHeight = float(0.25 * (scene.coverEdges.empty() ? longest : std::max(longest, double(scene.coverEdges[v]))));
    Vec3d lifted = p + n * offset;
    if (scene.vertexHidden[v]) {
        out.point = Vec3f(lifted);
        return out;  // casts nothing
    }
    // Off the walls of v's own mesh that stand on v, by 2 δ_v out of their front: the floor's side
    // of the wall's plane, not on it. Inside a surface the start leaves v's normal for nothing else:
    // a step along a face would put the faces round a smooth-shaded vertex in the way of its own
    // hemisphere (π on a smooth icosahedron under a sky, not a per-corner bake's 0.894 π).
    if (length(awayFromWalls) > 0) lifted += normalize(awayFromWalls) * (2 * offset);
    // At a border (an edge at v that one triangle alone uses: a sheet's edge, an open box's rim, a
    // crease's open end) v is the end of its surface, and the rays past the edge below the
    // surface's plane would escape that every point of the triangles beside v sees blocked. The
    // vertex stands for those triangles: its start steps 16 δ_v over them, toward their centroid
    // in v's tangent plane (at most a quarter of the way), lifted far less than it stepped, and
    // stops at half the distance to anything in the way.
    if (edges.border() && facingArea > 0) {
        const Vec3d toCentroid = facingCentroid / facingArea - p;
        const Vec3d tangential = toCentroid - unit * dot(toCentroid, unit);
        const double distance = length(tangential);
        if (distance > 1e-3 * length(toCentroid)) {
            const Vec3d u = tangential / distance;
            double step = std::min(kBorderStepOffsets * offset, 0.25 * distance);
            const auto hit = bvh.intersect(Vec3f(lifted), Vec3f(u), 0.0f, float(step));
            if (hit) step = 0.5 * double(hit->t);
            lifted += u * step;
        }
    }
    out.point = Vec3f(lifted);
    const OwnTriangles own{topology.trianglesBegin(v), topology.trianglesEnd(v)};
    // Inside other geometry, or on a surface through v that is not v's (a block's wall on v's foot
    // line, which rounding puts the start on either side of; the floor under a block's lowest row):
    // step sideways by 2 δ_v. A side point is inside something when the ray from it back to v's
    // lifted point and a little past leaves through a back face — robust, as the side point lies
    // off any plane through v — and then the point opposite it is where the open side is.
    Vec3f tangent, bitangent;
    orthonormalBasis(scene.normals[v], tangent, bitangent);
    const Vec3f probes[5] = {tangent, -tangent, bitangent, -bitangent, scene.normals[v]};
    Vec3f side[4];
    bool sideInside[4];
    for (int k = 0; k < 4; ++k) {
        side[k] = Vec3f(lifted + Vec3d(probes[k]) * (2 * offset));
        const Vec3f back = -probes[k];
        // On past the lifted point by δ_v: a surface through it (the floor under a block's lowest
        // vertex) is crossed well inside the ray, not at its end, where rounding would decide.
        const auto hit = bvh.intersect(side[k], back, 0.0f, float(3 * offset));
        sideInside[k] = hit && !own.contain(hit->triangle) && dot(frontNormals[hit->triangle], back) > 0;
    }
    StartProbe best = probeAround(out.point, probes, offset, bvh, frontNormals, own);
    if (acceptable(best, offset) && std::none_of(sideInside, sideInside + 4, [](bool b) { return b; })) return out;
    for (int k = 0; k < 4; ++k)
        if (!sideInside[k] && sideInside[k ^ 1]) {
            out.point = side[k];
            return out;
        }
    // Inside something larger than the step, or hemmed in all round: the clearest start, outside first.
    for (int k = 0; k < 4; ++k) {
        const StartProbe probe = probeAround(side[k], probes, offset, bvh, frontNormals, own);
        const bool better = probe.inside != best.inside ? !probe.inside : probe.clearance > best.clearance;
        if (!better) continue;
        best = probe;
        out.point = side[k];
    }
    return out;
}

void VertexStarts::computeAll(const Scene& scene, const SceneBvh& bvh) {
    starts_.assign(scene.vertexCount(), VertexStart{});
    normals_.assign(scene.normals.begin(), scene.normals.end());
    const MeshTopology topology(scene);
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 256), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) starts_[v] = vertexRayStart(scene, bvh, topology, frontNormals, v);
    });
}

std::vector<uint32_t> VertexStarts::update(const Scene& scene, const SceneBvh& bvh, const std::vector<Bounds3f>& movedBounds,
                                           const std::vector<uint8_t>& vertexMoved) {
    // A vertex that did not move keeps its offset unless one of its triangles moved, and then it
    // lies in that triangle's bounds: the boxes widened by its reach find every vertex whose
    // start may differ. The ray epsilon covers the widening's rounding, with room to spare.
    std::vector<uint8_t> touched(scene.vertexCount(), 0);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 1024), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            if (vertexMoved[v]) {
                touched[v] = 1;
                continue;
            }
            const float reach = kReachOffsets * starts_[v].offset + bvh.rayEpsilon();
            for (const Bounds3f& box : movedBounds)
                if (box.expanded(reach).contains(scene.positions[v])) {
                    touched[v] = 1;
                    break;
                }
        }
    });
    std::vector<uint32_t> changed;
    if (std::find(touched.begin(), touched.end(), uint8_t(1)) == touched.end()) return changed;
    const MeshTopology topology(scene);
    const std::vector<Vec3f> frontNormals = scene.frontFaceNormals();
    std::vector<uint8_t> differs(scene.vertexCount(), 0);
    tbb::parallel_for(tbb::blocked_range<uint32_t>(0, uint32_t(scene.vertexCount()), 1024), [&](const tbb::blocked_range<uint32_t>& r) {
        for (uint32_t v = r.begin(); v != r.end(); ++v) {
            if (!touched[v]) continue;
            const VertexStart start = vertexRayStart(scene, bvh, topology, frontNormals, v);
            // Bitwise: the rays are the same only if they start from the very same floats.
            differs[v] = std::memcmp(&start.point, &starts_[v].point, sizeof(Vec3f)) != 0 ||
                         std::memcmp(&scene.normals[v], &normals_[v], sizeof(Vec3f)) != 0;
            starts_[v] = start;
            normals_[v] = scene.normals[v];
        }
    });
    for (uint32_t v = 0; v < scene.vertexCount(); ++v)
        if (differs[v]) changed.push_back(v);
    return changed;
}

}  // namespace qsgi
