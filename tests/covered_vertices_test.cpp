// Covered vertices and the first pass the gather reads at a block's foot (issue 47 item 4,
// estimate/covered_vertices.h): a block standing on a floor, its foot cutting the floor's
// triangles at any fraction, against the closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "estimate/covered_vertices.h"
#include "estimate/final_gather.h"
#include "test_support.h"

using namespace qsgi;

namespace {
constexpr int kFloorCells = 32;       // a 4 m floor: 12.5 cm cells, edges at −2 + 0.125 i (exact floats)
constexpr float kFloorHalf = 2.0f;
constexpr float kBlockHeight = 0.6f;  // 4 cells a face: a 15 cm bottom row, as the block
constexpr int kBlockCells = 4;

// The block's foot at x, z = ±(0.25 + 0.125 f): it cuts the floor cells [0.25, 0.375] at fraction f;
// at f = 0 it stands exactly on a row of floor vertices.
float blockHalf(double fraction) { return float(0.25 + 0.125 * fraction); }

bool floorVertex(const Scene& scene, uint32_t v) { return v < scene.instances[0].vertexCount; }

// Where v lies against the block's footprint in world x, z: −1 strictly inside, 0 on the foot
// line (within 10⁻⁶ m), +1 outside.
int footprintSide(const Scene& scene, const Vec3d& p, float half) {
    (void)scene;
    const double d = std::max(std::abs(p.x), std::abs(p.z)) - double(half);
    return d < -1e-6 ? -1 : (d > 1e-6 ? 1 : 0);
}
Vec3d world(const Scene& scene, const Vec3f& p) { return Vec3d(p) + scene.worldOrigin; }
}  // namespace

// The floor's first pass is a constant c wherever light reaches it (0 under the block, and on the
// block). A vertex of the block's lowest row, on a vertical face at the foot, starts its gather
// rays a float error (δ_v, a few µm) off the floor: each ray that leaves downward lands on the floor within a
// hair of the foot, on the visible side, and each upward one escapes. The exact gathered value is
// therefore c × (the share of its rays pointing down) — whatever fraction of a floor triangle the
// foot cuts off. (A ray from a start 10⁻⁵ m up could miss the 4 m floor only below 10⁻⁵ rad; the
// barycentrics' 16-bit rounding moves a value by at most 2⁻¹⁶ of c.) Read as is, the cut
// triangles' covered corners (0) would darken that strip: the value fell with the fraction cut off.
// And the share is ½ to within the stratification of 256 Sobol points (2/256: a half-circle of
// angles is an interval of length ½ in the angle's dimension, in at most two pieces).
TEST(CoveredVertices, TheBlocksFootSeesTheFloorsOwnValueWhereverTheFootCutsItsTriangles) {
    const uint32_t M = 256;
    const float c = 0.5f;
    for (double fraction : {0.1, 0.5, 0.9, 0.0}) {
        SCOPED_TRACE("the foot cuts the floor's triangles at fraction " + std::to_string(fraction));
        const float half = blockHalf(fraction);
        const Scene scene = testscenes::blockOnFloor(kFloorCells, kFloorHalf, half, kBlockHeight, kBlockCells, Vec3f(0.5f));
        const SecondPassRig rig(scene);
        FinalGather gather(M, 11);
        gather.castAll(scene, rig.bvh, rig.starts);
        const std::vector<uint8_t> covered = gather.coveredFromKept(scene, rig.starts);

        // Covered: exactly the floor vertices strictly inside the footprint. Floor vertices on the
        // foot line (fraction 0) start outside the block (their side step goes outward) and are
        // not covered; nor is any vertex of the block.
        std::vector<Vec3f> first(scene.vertexCount(), Vec3f(0.0f));
        size_t inside = 0, onLine = 0;
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            if (!floorVertex(scene, v)) {
                EXPECT_FALSE(covered[v]) << "block vertex " << v;
                continue;
            }
            const int side = footprintSide(scene, world(scene, scene.positions[v]), half);
            inside += side < 0;
            onLine += side == 0;
            EXPECT_EQ(bool(covered[v]), side < 0) << "floor vertex " << v;
            if (side == 0) {
                EXPECT_EQ(footprintSide(scene, world(scene, rig.starts.point(v)), half), 1)
                    << "floor vertex " << v << " on the foot line starts inside the block";
            }
            if (side >= 0) first[v] = Vec3f(c);
        }
        EXPECT_GT(inside, 8u);
        EXPECT_EQ(onLine > 0, fraction == 0.0);

        std::vector<Vec3f> asRead = first, filled = first;
        fillCoveredFirstPass(scene, covered, filled);
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            if (!covered[v]) continue;
            EXPECT_EQ(filled[v].x, c) << "covered floor vertex " << v << " takes its neighbours' c";
        }
        std::vector<Vec3f> gathered, gatheredAsRead;
        gather.gather(scene, filled, gathered);
        gather.gather(scene, asRead, gatheredAsRead);

        size_t contacts = 0;
        double darkest = 1;
        for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
            const Vec3d p = world(scene, scene.positions[v]);
            if (floorVertex(scene, v) || std::abs(p.y) > 1e-6 || std::abs(scene.normals[v].y) > 1e-3f) continue;
            ++contacts;
            uint32_t down = 0, floorHits = 0;
            for (uint32_t j = 0; j < M; ++j) {
                down += FinalGather::rayDirection(gather.hit(v, j)).y < 0;
                const uint32_t t = gather.hit(v, j).triangle;
                floorHits += t < scene.instances[0].firstTriangle + scene.instances[0].triangleCount;
            }
            EXPECT_EQ(down, floorHits) << "contact vertex " << v << ": every downward ray lands on the floor";
            const double share = double(down) / M;
            EXPECT_NEAR(share, 0.5, 2.0 / M) << "contact vertex " << v;
            EXPECT_NEAR(gathered[v].x, c * share, c * (std::ldexp(1.0, -16) + 1e-6)) << "contact vertex " << v;
            darkest = std::min(darkest, double(gatheredAsRead[v].x) / (c * share));
        }
        EXPECT_EQ(contacts, size_t(4 * (kBlockCells + 1)));  // each face's bottom row, its corners its own
        // What the fill is for: read as is, the covered corners darken some contact vertex's view
        // (where the foot cuts triangles; on the vertex row no triangle straddles it).
        std::printf("fraction %.1f: %zu covered floor vertices; as read, the darkest contact vertex sees %.3f of c x share\n",
                    fraction, inside, darkest);
        if (fraction > 0) {
            EXPECT_LT(darkest, 0.97);
        }
    }
}
