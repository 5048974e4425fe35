// --refine-contacts (issue 47 item 3, lib/scene/contact_refinement.h): every edge that passes within
// DISTANCE of another piece of surface, in any frame, ends at most DISTANCE/2 long; edges far from
// any contact are left alone; the mesh stays conforming; the limit refuses before anything changes;
// and a render with it gives incremental frames byte-identical to full ones.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>

#include "scene/contact_refinement.h"
#include "scene/mesh_topology.h"
#include "scene/triangle_grid.h"
#include "test_support.h"

using namespace qsgi;
namespace fs = std::filesystem;

namespace {
constexpr double kDistance = 0.05;
constexpr float kBlockHalf = 0.3f;  // off the floor's 0.125 grid: the foot cuts its triangles

Scene blockScene() { return testscenes::blockOnFloor(16, 1.0f, kBlockHalf, 0.5f, 2, Vec3f(0.5f)); }

// Frame 1 moves the block 0.4 along x (frame 0 is the rest pose).
Pose poseAt(const Scene& scene, int frame) {
    std::vector<Transform> locals = scene.restLocals();
    if (frame == 1) locals[1] = Transform::fromTRS(Vec3d(0.4, 0, 0), {0, 0, 0, 1}, Vec3d(1.0));
    return Pose(locals);
}

// A pose of the refined scene with each triangle's bounds, made once.
struct PosedTriangles {
    const Scene& scene;
    const std::vector<uint32_t>& piece;
    std::vector<Bounds3f> bounds;
    std::map<std::pair<uint32_t, uint32_t>, double> distances;  // by edge (its corners, in order)
    PosedTriangles(const Scene& s, const std::vector<uint32_t>& pieces) : scene(s), piece(pieces) {
        for (const Triangle& T : s.triangles) {
            Bounds3f box;
            for (uint32_t v : T.v) box.extend(s.positions[v]);
            bounds.push_back(box);
        }
    }

    // The least distance from the edge va–vb of a triangle of `ownPiece` (sampled at 64 points) to a
    // triangle of another piece, by brute force over the triangles whose bounds come within
    // 2 DISTANCE of the edge's (farther: reported as 1). Each edge is measured once.
    double distanceToOtherPieces(uint32_t ownPiece, uint32_t va, uint32_t vb) {
        const auto key = std::minmax(va, vb);
        if (const auto it = distances.find(key); it != distances.end()) return it->second;
        const Vec3f &a = scene.positions[va], &b = scene.positions[vb];
        Bounds3f edge;
        edge.extend(a);
        edge.extend(b);
        edge = edge.expanded(float(2 * kDistance));
        std::vector<uint32_t> near;
        for (uint32_t t = 0; t < scene.triangleCount(); ++t)
            if (piece[t] != ownPiece && bounds[t].overlaps(edge)) near.push_back(t);
        double least = 1;
        for (int i = 0; i <= 64 && !near.empty(); ++i) {
            const Vec3d p = Vec3d(a) + (Vec3d(b) - Vec3d(a)) * (i / 64.0);
            for (uint32_t t : near) {
                const Triangle& T = scene.triangles[t];
                least = std::min(least, std::sqrt(squaredDistanceToTriangle(p, Vec3d(scene.positions[T.v[0]]),
                                                                              Vec3d(scene.positions[T.v[1]]),
                                                                              Vec3d(scene.positions[T.v[2]]))));
            }
        }
        return distances[key] = least;
    }
};

// Every edge of a piece used by two of its triangles, or by one on its border: the floor's outer
// edge, the block's foot (its bottom is open). Anything else is a T-junction.
void expectConforming(const Scene& scene, const std::vector<uint32_t>& piece) {
    std::map<std::pair<uint32_t, std::pair<std::array<float, 3>, std::array<float, 3>>>, int> uses;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t)
        for (int e = 0; e < 3; ++e) {
            const Vec3d a = Vec3d(scene.positions[scene.triangles[t].v[e]]) + scene.worldOrigin;
            const Vec3d b = Vec3d(scene.positions[scene.triangles[t].v[(e + 1) % 3]]) + scene.worldOrigin;
            std::array<float, 3> ka{float(a.x), float(a.y), float(a.z)}, kb{float(b.x), float(b.y), float(b.z)};
            if (kb < ka) std::swap(ka, kb);
            ++uses[{piece[t], {ka, kb}}];
        }
    for (const auto& [key, count] : uses) {
        const auto& [a, b] = key.second;
        const bool floorBorder = (std::fabs(a[0]) == 1.0f && a[0] == b[0]) || (std::fabs(a[2]) == 1.0f && a[2] == b[2]);
        const bool foot = a[1] == 0 && b[1] == 0 && key.first != piece[0];
        EXPECT_EQ(count, floorBorder || foot ? 1 : 2) << "edge (" << a[0] << ", " << a[1] << ", " << a[2] << ") to (" << b[0]
                                                       << ", " << b[1] << ", " << b[2] << ")";
    }
}
}  // namespace

TEST(ContactRefinement, EdgesNearAnotherPieceInAnyFrameEndShortAndTheRestAreLeftAlone) {
    const Scene before = blockScene();
    Scene scene = blockScene();
    const auto report = refineContacts(scene, kDistance, 1, [&](int f) { return poseAt(scene, f); }, SIZE_MAX);
    ASSERT_TRUE(report);
    EXPECT_EQ(report->posesJudged, 2);
    EXPECT_GT(report->mesh.verticesAfter, report->mesh.verticesBefore);
    EXPECT_EQ(report->mesh.verticesAfter, scene.vertexCount());
    const std::vector<uint32_t> piece = MeshTopology(scene.positions, scene.triangles).edgeConnectedPieces(scene.triangles);
    expectConforming(scene, piece);

    // The scene in frame 1's pose, for the distances there.
    Scene moved = scene;
    moved.applyPose(poseAt(moved, 1));
    // The rule measures at points DISTANCE/4 apart: it may miss by DISTANCE/8 (contact_refinement.h).
    const double sure = kDistance - kDistance / 8;
    PosedTriangles rest(scene, piece), frame1(moved, piece);
    size_t nearEdges = 0, farLongEdges = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t)
        for (int e = 0; e < 3; ++e) {
            const uint32_t va = scene.triangles[t].v[e], vb = scene.triangles[t].v[(e + 1) % 3];
            const double len = length(Vec3d(scene.positions[vb]) - Vec3d(scene.positions[va]));
            const double here = rest.distanceToOtherPieces(piece[t], va, vb);
            const double there = frame1.distanceToOtherPieces(piece[t], va, vb);
            if (std::min(here, there) <= sure) {
                ++nearEdges;
                EXPECT_LE(len, kContactEdgeShare * kDistance * (1 + 1e-6)) << "triangle " << t << " edge " << e << ", "
                                                                           << std::min(here, there) << " from another piece";
            }
            farLongEdges += len > kContactEdgeShare * kDistance;
        }
    EXPECT_GT(nearEdges, 100u);
    EXPECT_GT(farLongEdges, 100u);
    // Far from both of the block's places (0.5 m and more from the x range it covers) the floor is
    // as it was: the same triangles.
    auto farCount = [](const Scene& s) {
        size_t n = 0;
        for (uint32_t t = 0; t < s.instances[0].triangleCount; ++t) {
            const Triangle& T = s.triangles[s.instances[0].firstTriangle + t];
            const Vec3d c = (Vec3d(s.positions[T.v[0]]) + Vec3d(s.positions[T.v[1]]) + Vec3d(s.positions[T.v[2]])) / 3.0 + s.worldOrigin;
            n += std::abs(c.z) > kBlockHalf + 0.5;
        }
        return n;
    };
    EXPECT_EQ(farCount(scene), farCount(before));
}

TEST(ContactRefinement, MoreTrianglesThanTheLimitChangeNothing) {
    Scene scene = blockScene();
    const size_t triangles = scene.triangleCount(), vertices = scene.vertexCount();
    const auto report = refineContacts(scene, kDistance, 0, [&](int f) { return poseAt(scene, f); }, triangles + 10);
    EXPECT_FALSE(report);
    EXPECT_EQ(scene.triangleCount(), triangles);
    EXPECT_EQ(scene.vertexCount(), vertices);
}

// data/cornell refined at its block's contacts over the animation: incremental frames equal full
// ones to the byte, and the mesh is the same in every frame range (a chunk of a split run
// refines alike: frames 2:3 alone give frame 3's bytes).
TEST(ContactRefinement, ARefinedRenderUpdatesIncrementallyToTheFullRecomputationsBytes) {
    const fs::path cornell = sourceDir() / "data" / "cornell";
    const std::string base = "render " + (cornell / "cornell.gltf").string() + " --animation " + (cornell / "animation.json").string() +
                             " --photons 20000 --gather 16 --direct-samples 4 --no-exr --quiet --refine-contacts 0.05";
    const fs::path dir = testScratchDir("contact-refinement");
    const CommandResult inc = runQsgi(base + " --frames 0:3 --out '" + (dir / "inc").string() + "'");
    ASSERT_EQ(inc.exitCode, 0) << inc.output;
    const CommandResult full = runQsgi(base + " --frames 0:3 --full-recompute --out '" + (dir / "full").string() + "'");
    ASSERT_EQ(full.exitCode, 0) << full.output;
    const CommandResult chunk = runQsgi(base + " --frames 2:3 --out '" + (dir / "chunk").string() + "'");
    ASSERT_EQ(chunk.exitCode, 0) << chunk.output;
    for (const char* frame : {"frame_0000.ply", "frame_0001.ply", "frame_0002.ply", "frame_0003.ply"}) {
        const std::string bytes = readFileBytes(dir / "inc" / frame);
        ASSERT_FALSE(bytes.empty()) << frame;
        EXPECT_EQ(bytes, readFileBytes(dir / "full" / frame)) << frame;
    }
    EXPECT_EQ(readFileBytes(dir / "inc" / "frame_0003.ply"), readFileBytes(dir / "chunk" / "frame_0003.ply"));
}
