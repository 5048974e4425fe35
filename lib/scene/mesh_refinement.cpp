#include "scene/mesh_refinement.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <tuple>
#include <unordered_map>
#include <utility>
#include <vector>

namespace qsgi {

namespace {

using LocalTriangle = std::array<uint32_t, 3>;

// appendRefinedValues for the scene's Vec3f arrays.
void appendRefinedVectors(std::vector<Vec3f>& values, const std::vector<std::pair<uint32_t, uint32_t>>& refinedFrom,
                          RefinedRule rule) {
    values.reserve(values.size() + refinedFrom.size());
    for (const auto& [a, b] : refinedFrom) {
        const float p[3] = {values[a].x, values[a].y, values[a].z}, q[3] = {values[b].x, values[b].y, values[b].z};
        float m[3];
        refinedValue(p, q, m, 3, rule);
        values.push_back(Vec3f(m[0], m[1], m[2]));
    }
}

// One instance's vertices (local indices) and triangles, growing as edges are split.
class InstanceRefiner {
public:
    // tracks: per tracked pose, every scene vertex's world position (RefinementTracks); pieces: the
    // scene triangles' pieces (RefinementTracks::pieces), or empty.
    InstanceRefiner(const Scene& scene, const MeshInstance& inst, const RefinementTracks* tracks = nullptr)
        : inst_(inst), positions_(inst.objectPositions), normals_(inst.objectNormals), joints_(inst.skinJoints),
          weights_(inst.skinWeights), morphPositions_(inst.morphPositions), morphNormals_(inst.morphNormals) {
        // What the materials read per vertex (issue 57), the block's own values, flattened.
        for (const std::vector<TexCoord>& set : scene.vertexTexCoords) {
            std::vector<float>& uv = texCoords_.emplace_back();
            for (uint32_t i = 0; i < inst.vertexCount && !set.empty(); ++i)
                uv.insert(uv.end(), {set[inst.firstVertex + i].s, set[inst.firstVertex + i].t});
        }
        for (uint32_t i = 0; i < inst.vertexCount && !scene.vertexColours.empty(); ++i) {
            const Rgba& c = scene.vertexColours[inst.firstVertex + i];
            colours_.insert(colours_.end(), c.begin(), c.end());
        }
        world_.reserve(inst.vertexCount);
        for (uint32_t i = 0; i < inst.vertexCount; ++i) world_.push_back(Vec3d(scene.positions[inst.firstVertex + i]));
        for (uint32_t t = 0; t < inst.triangleCount; ++t) {
            const Triangle& tri = scene.triangles[inst.firstTriangle + t];
            triangles_.push_back({tri.v[0] - inst.firstVertex, tri.v[1] - inst.firstVertex, tri.v[2] - inst.firstVertex});
            piece_.push_back(tracks && !tracks->pieces.empty() ? tracks->pieces[inst.firstTriangle + t] : 0);
        }
        if (tracks)
            for (const std::vector<Vec3f>& pose : tracks->poses)
                tracks_.emplace_back(pose.begin() + inst.firstVertex, pose.begin() + inst.firstVertex + inst.vertexCount);
    }

    // Splits until no edge needs it: `needs(length, piece, a, b)` for an edge of `length` (current
    // pose) between local vertices a and b of a triangle of `piece`. A pure function of the edge, so
    // both triangles of an edge agree and no T-junction is left. Returns false, leaving the instance
    // partly refined, as soon as more than `triangleLimit` triangles would be made.
    template <typename Needs>
    bool refine(Needs&& needs, size_t triangleLimit) {
        for (bool changed = true; changed;) {
            changed = false;
            std::vector<LocalTriangle> next;
            std::vector<uint32_t> nextPiece;
            next.reserve(std::min(triangles_.size() * 2, triangleLimit));
            for (size_t i = 0; i < triangles_.size(); ++i) {
                // Refused as soon as the limit is passed, not after a pass that may double the mesh.
                if (next.size() > triangleLimit) return false;
                const LocalTriangle& t = triangles_[i];
                const int e = edgeToSplit(t, [&](double len, uint32_t a, uint32_t b) { return needs(len, piece_[i], a, b); });
                if (e < 0) {
                    next.push_back(t);
                    nextPiece.push_back(piece_[i]);
                    continue;
                }
                const uint32_t p = t[size_t(e)], q = t[size_t(e + 1) % 3], r = t[size_t(e + 2) % 3];
                const uint32_t m = midpoint(p, q);
                // (p, q, r) counter-clockwise gives (p, m, r) and (m, q, r), counter-clockwise.
                next.push_back({p, m, r});
                next.push_back({m, q, r});
                nextPiece.insert(nextPiece.end(), 2, piece_[i]);
                changed = true;
            }
            triangles_ = std::move(next);
            piece_ = std::move(nextPiece);
            if (triangles_.size() > triangleLimit) return false;
        }
        return true;
    }

    size_t triangleCount() const { return triangles_.size(); }
    // Vertex v's world position in tracked pose k.
    const Vec3f& tracked(size_t k, uint32_t v) const { return tracks_[k][v]; }

    // Writes the refined instance back: its object-space data, and its block of the scene's arrays
    // from `firstVertex` and `firstTriangle` on.
    void store(MeshInstance& inst, Scene& scene, uint32_t firstVertex, uint32_t firstTriangle, uint32_t material,
               uint32_t triangleMaterial) {
        // The added vertices' object-space data, by the one rule (each reads only earlier vertices).
        appendRefinedVectors(positions_, refinedFrom_, RefinedRule::Mean);
        if (!normals_.empty()) appendRefinedVectors(normals_, refinedFrom_, RefinedRule::UnitNormal);
        for (std::vector<Vec3f>& target : morphPositions_) appendRefinedVectors(target, refinedFrom_, RefinedRule::Mean);
        for (std::vector<Vec3f>& target : morphNormals_)
            if (!target.empty()) appendRefinedVectors(target, refinedFrom_, RefinedRule::Mean);
        for (std::vector<float>& uv : texCoords_)
            if (!uv.empty()) appendRefinedValues(uv, 2, refinedFrom_, RefinedRule::Mean);
        if (!colours_.empty()) appendRefinedValues(colours_, 4, refinedFrom_, RefinedRule::Mean);
        inst.firstVertex = firstVertex;
        inst.vertexCount = uint32_t(world_.size());
        inst.firstTriangle = firstTriangle;
        inst.triangleCount = uint32_t(triangles_.size());
        inst.objectPositions = std::move(positions_);
        inst.objectNormals = std::move(normals_);
        inst.skinJoints = std::move(joints_);
        inst.skinWeights = std::move(weights_);
        inst.morphPositions = std::move(morphPositions_);
        inst.morphNormals = std::move(morphNormals_);
        inst.refinedFrom.insert(inst.refinedFrom.end(), refinedFrom_.begin(), refinedFrom_.end());
        for (uint32_t i = 0; i < inst.vertexCount; ++i) {
            scene.positions.push_back(Vec3f(0.0f));
            scene.normals.push_back(Vec3f(0.0f));
            scene.vertexHidden.push_back(0);
            scene.vertexMaterial.push_back(material);
        }
        for (size_t set = 0; set < texCoords_.size(); ++set)
            for (uint32_t i = 0; i < inst.vertexCount; ++i)
                scene.vertexTexCoords[set].push_back(texCoords_[set].empty() ? TexCoord()
                                                                             : TexCoord{texCoords_[set][2 * i], texCoords_[set][2 * i + 1]});
        for (uint32_t i = 0; i < inst.vertexCount && !colours_.empty(); ++i)
            scene.vertexColours.push_back({colours_[4 * i], colours_[4 * i + 1], colours_[4 * i + 2], colours_[4 * i + 3]});
        for (const LocalTriangle& t : triangles_) {
            scene.triangles.push_back({{firstVertex + t[0], firstVertex + t[1], firstVertex + t[2]}});
            scene.triangleMaterial.push_back(triangleMaterial);
        }
    }

private:

    double edgeLength(uint32_t a, uint32_t b) const { return length(world_[b] - world_[a]); }

    // The edge (0, 1, 2: from corner e to corner e + 1) to split: the longest of those that need it
    // (needs(length, a, b), asked with the corners in increasing order); else −1.
    template <typename Needs>
    int edgeToSplit(const LocalTriangle& t, Needs&& needs) const {
        int longest = -1;
        double longestLength = 0;
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = t[size_t(e)], b = t[size_t(e + 1) % 3];
            const double len = edgeLength(a, b);
            if (len > longestLength && needs(len, std::min(a, b), std::max(a, b))) longest = e, longestLength = len;
        }
        return longest;
    }

    // The vertex halfway along a–b, made once per pair of corners.
    uint32_t midpoint(uint32_t a, uint32_t b) {
        const std::pair<uint32_t, uint32_t> pair(std::min(a, b), std::max(a, b));
        const auto found = midpoints_.find(pair);
        if (found != midpoints_.end()) return found->second;
        const uint32_t m = uint32_t(world_.size());
        midpoints_.emplace(pair, m);
        refinedFrom_.push_back({a, b});
        world_.push_back((world_[a] + world_[b]) * 0.5);
        for (std::vector<Vec3f>& track : tracks_) track.push_back(Vec3f((Vec3d(track[a]) + Vec3d(track[b])) * 0.5));
        if (inst_.influences > 0) blendInfluences(a, b);
        return m;
    }

    // The union of a's and b's joint influences at half weight each, the largest kept.
    void blendInfluences(uint32_t a, uint32_t b) {
        const size_t k = size_t(inst_.influences);
        std::map<uint16_t, double> weightOf;
        for (uint32_t corner : {a, b})
            for (size_t i = 0; i < k; ++i) {
                const double w = weights_[corner * k + i];
                if (w > 0) weightOf[joints_[corner * k + i]] += 0.5 * w;
            }
        std::vector<std::pair<double, uint16_t>> ranked;
        for (const auto& [joint, w] : weightOf) ranked.push_back({w, joint});
        // By weight, the lower joint first among equals: the same vertex on both sides of a seam.
        std::sort(ranked.begin(), ranked.end(), [](const auto& x, const auto& y) {
            return x.first != y.first ? x.first > y.first : x.second < y.second;
        });
        ranked.resize(std::min(ranked.size(), k));
        double total = 0;
        for (const auto& r : ranked) total += r.first;
        for (size_t i = 0; i < k; ++i) {
            const bool used = i < ranked.size() && total > 0;
            joints_.push_back(used ? ranked[i].second : 0);
            weights_.push_back(used ? float(ranked[i].first / total) : 0.0f);
        }
    }

    const MeshInstance& inst_;
    std::vector<Vec3f> positions_, normals_;
    std::vector<uint16_t> joints_;
    std::vector<float> weights_;
    std::vector<std::vector<Vec3f>> morphPositions_, morphNormals_;
    std::vector<std::vector<float>> texCoords_;  // per TEXCOORD set, 2 floats a vertex
    std::vector<float> colours_;                 // COLOR_0, 4 floats a vertex, or none
    std::vector<Vec3d> world_;  // the current pose's, for lengths
    std::vector<LocalTriangle> triangles_;
    std::vector<uint32_t> piece_;                 // per triangle: its piece of surface (RefinementTracks)
    std::vector<std::vector<Vec3f>> tracks_;      // per tracked pose, per vertex: its world position
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints_;
    std::vector<std::pair<uint32_t, uint32_t>> refinedFrom_;  // per new vertex, in order
};

}  // namespace

void refinedValue(const float* a, const float* b, float* out, size_t components, RefinedRule rule) {
    const size_t mean = rule == RefinedRule::Mean ? components : 0;
    for (size_t k = 0; k < mean; ++k) out[k] = float((double(a[k]) + double(b[k])) * 0.5);
    if (rule == RefinedRule::Mean) return;
    const Vec3d n = Vec3d(a[0], a[1], a[2]) + Vec3d(b[0], b[1], b[2]);
    // Opposite directions (a knife edge) have no mean: take a corner's.
    const Vec3f unit = dot(n, n) > 0 ? Vec3f(normalize(n)) : Vec3f(a[0], a[1], a[2]);
    out[0] = unit.x, out[1] = unit.y, out[2] = unit.z;
    for (size_t k = 3; k < components; ++k) out[k] = a[k];  // a tangent's handedness
}

void appendRefinedValues(std::vector<float>& values, size_t components,
                         const std::vector<std::pair<uint32_t, uint32_t>>& refinedFrom, RefinedRule rule) {
    values.reserve(values.size() + refinedFrom.size() * components);
    std::vector<float> value(components);
    for (const auto& [a, b] : refinedFrom) {
        refinedValue(&values[size_t(a) * components], &values[size_t(b) * components], value.data(), components, rule);
        values.insert(values.end(), value.begin(), value.end());
    }
}

namespace {
// Writes the refiners' instances back into the scene and re-places them.
RefinementReport storeRefined(Scene& scene, std::vector<InstanceRefiner>& refiners, RefinementReport report);
}  // namespace

RefinementReport refineMesh(Scene& scene, double maxEdge) { return *refineMesh(scene, maxEdge, SIZE_MAX); }

std::optional<RefinementReport> refineMesh(Scene& scene, double maxEdge, size_t triangleLimit) {
    RefinementReport report;
    report.trianglesBefore = scene.triangleCount();
    report.verticesBefore = scene.vertexCount();
    std::vector<InstanceRefiner> refiners;
    size_t made = 0;
    for (const MeshInstance& inst : scene.instances) {
        refiners.emplace_back(scene, inst);
        if (!refiners.back().refine([&](double len, uint32_t, uint32_t, uint32_t) { return len > maxEdge; },
                                    triangleLimit - std::min(triangleLimit, made)))
            return std::nullopt;
        made += refiners.back().triangleCount();
    }
    return storeRefined(scene, refiners, report);
}

RefinementReport bisectEveryEdge(Scene& scene) {
    RefinementReport report;
    report.trianglesBefore = scene.triangleCount();
    report.verticesBefore = scene.vertexCount();
    std::vector<InstanceRefiner> refiners;
    for (const MeshInstance& inst : scene.instances) {
        refiners.emplace_back(scene, inst);
        // An edge between two of the mesh's own vertices is split (once: its halves end at the new
        // midpoint); a degenerate one is not (edgeToSplit never splits a zero length).
        const uint32_t own = inst.vertexCount;
        refiners.back().refine([&](double, uint32_t, uint32_t a, uint32_t b) { return a < own && b < own; }, SIZE_MAX);
    }
    return storeRefined(scene, refiners, report);
}

std::optional<RefinementReport> refineMeshWhere(Scene& scene, const RefinementTracks& tracks, const EdgeSplitTest& needs,
                                                size_t triangleLimit) {
    RefinementReport report;
    report.trianglesBefore = scene.triangleCount();
    report.verticesBefore = scene.vertexCount();
    std::vector<InstanceRefiner> refiners;
    size_t made = 0;
    std::vector<Vec3f> a(tracks.poses.size()), b(tracks.poses.size());
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        refiners.emplace_back(scene, scene.instances[i], &tracks);
        InstanceRefiner& refiner = refiners.back();
        // Each pass asks about every edge of every triangle again: an edge's answer is kept.
        std::unordered_map<uint64_t, bool> decided;
        const bool within = refiner.refine(
            [&](double len, uint32_t piece, uint32_t p, uint32_t q) {
                const auto [it, added] = decided.emplace(uint64_t(p) << 32 | q, false);
                if (!added) return it->second;
                // The corners in the order of their places, not their indices: the two sides of a
                // seam (corners duplicated for their normals) ask about the same edge with the same
                // floats, and so agree to the bit.
                const Vec3f &pAt = refiner.tracked(0, p), &qAt = refiner.tracked(0, q);
                if (std::tie(qAt.x, qAt.y, qAt.z) < std::tie(pAt.x, pAt.y, pAt.z)) std::swap(p, q);
                for (size_t k = 0; k < a.size(); ++k) a[k] = refiner.tracked(k, p), b[k] = refiner.tracked(k, q);
                return it->second = needs(EdgeToSplit{i, piece, len, a, b});
            },
            triangleLimit - std::min(triangleLimit, made));
        if (!within) return std::nullopt;
        made += refiner.triangleCount();
    }
    return storeRefined(scene, refiners, report);
}

namespace {
RefinementReport storeRefined(Scene& scene, std::vector<InstanceRefiner>& refiners, RefinementReport report) {
    std::vector<uint32_t> materials, triangleMaterials;
    for (const MeshInstance& inst : scene.instances) {
        materials.push_back(inst.vertexCount ? scene.vertexMaterial[inst.firstVertex] : 0);
        triangleMaterials.push_back(inst.triangleCount ? scene.triangleMaterial[inst.firstTriangle] : 0);
    }
    scene.positions.clear();
    scene.normals.clear();
    scene.vertexHidden.clear();
    scene.coverEdges.clear();  // a sampling mesh refined again samples its own resolution
    scene.vertexMaterial.clear();
    for (std::vector<TexCoord>& set : scene.vertexTexCoords) set.clear();
    scene.vertexColours.clear();
    scene.triangles.clear();
    scene.triangleMaterial.clear();
    for (size_t i = 0; i < scene.instances.size(); ++i)
        refiners[i].store(scene.instances[i], scene, uint32_t(scene.positions.size()), uint32_t(scene.triangles.size()),
                          materials[i], triangleMaterials[i]);
    for (size_t i = 0; i < scene.instances.size(); ++i)
        scene.placeInstance(i, scene.placedWith[i], scene.placedJoints[i], scene.placedWeights[i]);
    scene.markDynamic({});
    report.trianglesAfter = scene.triangleCount();
    report.verticesAfter = scene.vertexCount();
    return report;
}
}  // namespace

size_t estimatedRefinedTriangles(const Scene& scene, double maxEdge) {
    double total = 0;
    for (const Triangle& t : scene.triangles) {
        double longest = 0;
        for (int e = 0; e < 3; ++e)
            longest = std::max(longest, length(Vec3d(scene.positions[t.v[(e + 1) % 3]]) - Vec3d(scene.positions[t.v[e]])));
        const double pieces = std::max(1.0, std::ceil(longest / maxEdge));
        total += pieces * pieces;
    }
    return total < 1e18 ? size_t(total) : size_t(1e18);
}

}  // namespace qsgi
