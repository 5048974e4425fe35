#include "scene/contact_refinement.h"

#include <algorithm>
#include <cmath>

#include "scene/mesh_topology.h"
#include "scene/triangle_grid.h"
#include "util/memory.h"

namespace qsgi {

namespace {
constexpr double kTrackBudgetBytes = double(1u << 30);
constexpr double kMostSamples = 4096;

// The frames judged: all of 0…lastFrame, or as many evenly spaced (first and last kept) as the budget holds.
std::vector<int> framesJudged(int lastFrame, size_t vertices) {
    const double perPose = double(vertices) * sizeof(Vec3f);
    const int most = std::max(2, int(std::min(double(lastFrame + 1), kTrackBudgetBytes / std::max(perPose, 1.0))));
    std::vector<int> frames;
    if (lastFrame + 1 <= most) {
        for (int f = 0; f <= lastFrame; ++f) frames.push_back(f);
        return frames;
    }
    for (int k = 0; k < most; ++k) frames.push_back(int(std::lround(double(k) * lastFrame / (most - 1))));
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    return frames;
}
}  // namespace

std::optional<ContactRefinementReport> refineContacts(Scene& scene, double distance, int lastFrame,
                                                      const std::function<Pose(int)>& poseAt, size_t triangleLimit) {
    // Where every vertex is in each judged pose; the rest pose first (it is frame 0's).
    RefinementTracks tracks;
    tracks.poses.push_back(scene.positions);
    const std::vector<int> frames = framesJudged(lastFrame, scene.vertexCount());
    bool anyMoved = false;
    for (int frame : frames) {
        if (frame == 0) continue;  // the rest pose
        if (!scene.applyPose(poseAt(frame))) continue;
        tracks.poses.push_back(scene.positions);
        anyMoved = true;
    }
    if (anyMoved) scene.applyPose(scene.restPose());
    const MeshTopology topology(scene);
    tracks.pieces = topology.edgeConnectedPieces(scene.triangles);

    // Triangles that move in some pose are looked for in each pose; the others once.
    std::vector<uint8_t> vertexMoves(scene.vertexCount(), 0);
    for (size_t k = 1; k < tracks.poses.size(); ++k)
        for (size_t v = 0; v < scene.vertexCount(); ++v)
            vertexMoves[v] |= !(tracks.poses[k][v] == tracks.poses[0][v]);
    std::vector<uint8_t> triangleMoves(scene.triangleCount()), triangleStays(scene.triangleCount());
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
        const Triangle& T = scene.triangles[t];
        triangleMoves[t] = vertexMoves[T.v[0]] | vertexMoves[T.v[1]] | vertexMoves[T.v[2]];
        triangleStays[t] = !triangleMoves[t];
    }
    const float reach = float(distance);
    const TriangleGrid still(tracks.poses[0], scene.triangles, reach, triangleStays);
    std::vector<TriangleGrid> moving;
    for (const std::vector<Vec3f>& pose : tracks.poses) moving.emplace_back(pose, scene.triangles, reach, triangleMoves);

    const double d2 = distance * distance, fine = kContactEdgeShare * distance;
    const std::vector<Triangle>& triangles = scene.triangles;
    auto nearOtherPiece = [&](const TriangleGrid& grid, const std::vector<Vec3f>& pose, const Vec3d& p, uint32_t piece) {
        return grid.anyNear(p, [&](uint32_t t) {
            const Triangle& T = triangles[t];
            return tracks.pieces[t] != piece &&
                   squaredDistanceToTriangle(p, Vec3d(pose[T.v[0]]), Vec3d(pose[T.v[1]]), Vec3d(pose[T.v[2]])) <= d2;
        });
    };
    const EdgeSplitTest needs = [&](const EdgeToSplit& e) {
        if (!(e.length > fine)) return false;
        // Points at most DISTANCE/4 apart in every pose (a deforming edge may be longer in some).
        double longest = e.length;
        for (size_t k = 0; k < e.a.size(); ++k) longest = std::max(longest, length(Vec3d(e.b[k]) - Vec3d(e.a[k])));
        const double spacing = 0.5 * fine;
        // An edge more than kMostSamples spacings long is split without asking (its halves are
        // asked in turn): no point it could pass near is skipped, and the count of samples stays
        // bounded whatever DISTANCE is.
        if (!(longest <= kMostSamples * spacing)) return true;
        const int steps = std::max(1, int(std::ceil(longest / spacing)));
        bool edgeMoves = false;
        for (size_t k = 1; k < e.a.size() && !edgeMoves; ++k) edgeMoves = !(e.a[k] == e.a[0]) || !(e.b[k] == e.b[0]);
        for (size_t k = 0; k < e.a.size(); ++k) {
            const bool askStill = k == 0 || edgeMoves;
            if (!askStill && moving[k].empty()) continue;
            for (int i = 0; i <= steps; ++i) {
                const double s = double(i) / steps;
                const Vec3d p = Vec3d(e.a[k]) * (1 - s) + Vec3d(e.b[k]) * s;
                if (askStill && nearOtherPiece(still, tracks.poses[0], p, e.piece)) return true;
                if (!moving[k].empty() && nearOtherPiece(moving[k], tracks.poses[k], p, e.piece)) return true;
            }
        }
        return false;
    };
    // The refiner follows each new vertex through every judged pose (12 bytes a pose, about half a
    // vertex a triangle): those tracks must fit the memory too, whatever the caller's limit.
    const uint64_t trackBytesPerTriangle = sizeof(Vec3f) * tracks.poses.size() / 2 + 1;
    triangleLimit = size_t(std::min<uint64_t>(triangleLimit, usableMemory().bytes / trackBytesPerTriangle));
    const std::optional<RefinementReport> mesh = refineMeshWhere(scene, tracks, needs, triangleLimit);
    if (!mesh) return std::nullopt;
    return ContactRefinementReport{*mesh, int(frames.size())};
}

}  // namespace qsgi
