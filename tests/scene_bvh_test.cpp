// Identical hits (docs/design.md §6 step 0): at equal t the lowest triangle id wins, inside the static and
// the dynamic BVH and between them, so no hit depends on a BVH's shape or traversal order.
#include <gtest/gtest.h>

#include <limits>

#include "trace/scene_bvh.h"
#include "trace/envelope.h"
#include "test_support.h"

using namespace qsgi;

namespace {

// Two unit quads in the plane y = 0 over [0,1]², as separate instances (triangles 0–1, 2–3),
// the diagonal from (0,0,0) to (1,0,1) shared inside each quad.
Scene coincidentQuads(bool firstDynamic, bool secondDynamic) {
    Scene s;
    s.materials.push_back(Material{"grey", Vec3f(0.5f), Vec3f(0.0f)});
    const std::vector<Vec3f> p = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    const std::vector<Vec3f> n(4, Vec3f(0, 1, 0));
    const std::vector<uint32_t> idx = {0, 2, 1, 0, 3, 2};
    const int a = s.addNode("A", Transform()), b = s.addNode("B", Transform());
    s.addInstance(a, p, n, idx, 0);
    s.addInstance(b, p, n, idx, 0);
    s.finalize();
    std::vector<int> moving;
    if (firstDynamic) moving.push_back(a);
    if (secondDynamic) moving.push_back(b);
    s.markDynamic(moving);
    return s;
}

}  // namespace

TEST(SceneBvh, EqualDistancesGoToTheLowestTriangleId) {
    EmbreeDevice device;
    for (auto [firstDynamic, secondDynamic] : {std::pair{false, false}, {true, true}, {false, true}, {true, false}}) {
        SCOPED_TRACE(std::to_string(firstDynamic) + std::to_string(secondDynamic));
        const Scene s = coincidentQuads(firstDynamic, secondDynamic);
        const SceneBvh bvh(device, s);
        // Rays straight down through a grid of points; re-centring moved the quads by
        // worldOrigin, so aim at their current positions.
        const Vec3f corner = s.positions[0];
        int onDiagonal = 0;
        for (int i = 1; i < 16; ++i)
            for (int j = 1; j < 16; ++j) {
                const Vec3f target = corner + Vec3f(float(i) / 16, 0, float(j) / 16);
                const auto hit = bvh.intersect(target + Vec3f(0, 1, 0), Vec3f(0, -1, 0), 0, 10);
                ASSERT_TRUE(hit);
                // The coincident copy (ids 2, 3) never wins; on the shared diagonal (i == j) both
                // triangles of the quad are hit at the same t and the lower id (0) wins.
                EXPECT_LT(hit->triangle, 2u) << i << "," << j;
                if (i == j) {
                    EXPECT_EQ(hit->triangle, 0u) << i;
                    ++onDiagonal;
                }
            }
        EXPECT_EQ(onDiagonal, 15);
    }
}

// intersect() asks the dynamic BVH only when the ray meets the dynamic triangles' padded bounds
// before the static hit. Checked against occluded(), which asks both BVHs along its own path: for
// every ray the closest hit leaves nothing nearer and something at it, and a miss nothing at all.
// Rays aimed at the moved cube (and dealt at random around it) make sure both the dynamic hits and
// the skipped rays occur, with the cube moved from where its BVH was built.
TEST(SceneBvh, ClosestHitsAgreeWithOcclusionAroundAMover) {
    Scene scene = testscenes::boxOnFloor(16, 3, Vec3f(0.7f));
    int cube = -1;
    for (size_t i = 0; i < scene.nodes.size(); ++i)
        if (scene.nodes[i].name == "Cube") cube = int(i);
    ASSERT_GE(cube, 0);
    scene.markDynamic({cube});
    EmbreeDevice device;
    SceneBvh bvh(device, scene);
    std::vector<Transform> locals = scene.restLocals();
    locals[size_t(cube)] = Transform::fromTRS(Vec3d(0.4, 0.05, -0.3), {0, 0, 0, 1}, Vec3d(1.0)) * locals[size_t(cube)];
    scene.applyPose(Pose(locals));
    bvh.updateDynamic(scene);
    std::vector<uint32_t> cubeTriangles;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t)
        if (scene.triangleDynamic[t]) cubeTriangles.push_back(t);
    ASSERT_FALSE(cubeTriangles.empty());
    const Bounds3f b = scene.animationBounds.expanded(0.5f);
    uint64_t state = 12345;
    auto uniform = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return float(state >> 40) / float(1 << 24);
    };
    int dynamicHits = 0, staticHits = 0, misses = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f origin(b.lower.x + uniform() * (b.upper.x - b.lower.x), b.lower.y + uniform() * (b.upper.y - b.lower.y),
                           b.lower.z + uniform() * (b.upper.z - b.lower.z));
        Vec3f direction;
        if (i % 2 == 0) {  // at a point inside one of the cube's triangles
            const Triangle& t = scene.triangles[cubeTriangles[size_t(uniform() * float(cubeTriangles.size())) % cubeTriangles.size()]];
            const float u = 0.05f + 0.45f * uniform(), v = 0.05f + 0.45f * uniform();
            direction = normalize(scene.positions[t.v[0]] * (1 - u - v) + scene.positions[t.v[1]] * u + scene.positions[t.v[2]] * v - origin);
        } else {
            direction = normalize(Vec3f(2 * uniform() - 1, 2 * uniform() - 1, 2 * uniform() - 1));
        }
        if (!(length(direction) > 0)) continue;
        const auto hit = bvh.intersect(origin, direction, 0.0f, std::numeric_limits<float>::infinity());
        if (!hit) {
            ++misses;
            EXPECT_FALSE(bvh.occluded(origin, direction, 0.0f, std::numeric_limits<float>::infinity())) << "ray " << i;
            continue;
        }
        (scene.triangleDynamic[hit->triangle] ? dynamicHits : staticHits)++;
        EXPECT_FALSE(bvh.occluded(origin, direction, 0.0f, hit->t * (1 - 1e-4f))) << "ray " << i << ": something nearer";
        EXPECT_TRUE(bvh.occluded(origin, direction, 0.0f, hit->t * (1 + 1e-4f))) << "ray " << i << ": nothing at the hit";
    }
    EXPECT_GT(dynamicHits, 1000);
    EXPECT_GT(staticHits, 1000);
    EXPECT_GT(misses, 100);
}

// The disc regions' shortcut (docs/design.md §5): a static triangle near the ball counts only if
// a corner rises to the asked height above the plane; coplanar and lower triangles never do.
TEST(SceneBvh, StaticGeometryRisesOnlyWhereACornerReachesTheHeight) {
    Scene s;
    s.materials.push_back(Material{"grey", Vec3f(0.5f), Vec3f(0.0f)});
    const std::vector<Vec3f> floor = {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}};
    const std::vector<Vec3f> up(4, Vec3f(0, 1, 0));
    const std::vector<uint32_t> quad = {0, 2, 1, 0, 3, 2};
    s.addInstance(s.addNode("floor", Transform()), floor, up, quad, 0);
    // A small raised triangle over the floor's far corner, 0.3 up.
    const std::vector<Vec3f> raised = {{0.9f, 0.3f, 0.9f}, {1.0f, 0.3f, 0.9f}, {0.9f, 0.3f, 1.0f}};
    s.addInstance(s.addNode("raised", Transform()), raised, std::vector<Vec3f>(3, Vec3f(0, -1, 0)), {0, 1, 2}, 0);
    s.finalize();
    EmbreeDevice device;
    const SceneBvh bvh(device, s);
    const Vec3f at = s.positions[0] + Vec3f(0.2f, 0, 0.2f);  // re-centred: relative to a corner
    const double inf = std::numeric_limits<double>::infinity();
    // The floor is in every ball around `at`, level with it; the raised triangle is 1.04 away.
    EXPECT_FALSE(bvh.staticGeometryRises(at, 0.3f, Vec3f(0, 1, 0), 1e-6));
    EXPECT_TRUE(bvh.staticGeometryRises(at, 0.3f, Vec3f(0, 1, 0), -inf));
    EXPECT_TRUE(bvh.staticGeometryRises(at, 0.3f, Vec3f(0, 1, 0), -1e-6));  // level counts below 0
    EXPECT_TRUE(bvh.staticGeometryRises(at, 1.2f, Vec3f(0, 1, 0), 1e-6));
    EXPECT_FALSE(bvh.staticGeometryRises(at, 1.2f, Vec3f(0, 1, 0), 0.31));  // above the raised one too
    // Seen from under the floor the raised triangle is below the plane.
    EXPECT_FALSE(bvh.staticGeometryRises(at, 1.2f, Vec3f(0, -1, 0), 1e-6));
}

TEST(Envelope, SegmentsMeetItWithTheirExtensionAndEscapingOnesWithoutEnd) {
    Scene s = testscenes::boxOnFloor(2, 1, Vec3f(0.5f));
    Bounds3f mover;
    mover.extend(Vec3f(0, 0, 0));
    mover.extend(Vec3f(1, 1, 1));
    s.sweptBoxes = {mover};
    const Envelope e = Envelope::ofAnimation(s, 0.1f);
    Segment seg;
    seg.origin = Vec3f(-2, 0.5f, 0.5f);
    seg.direction = Vec3f(1, 0, 0);
    seg.triangle = 0;
    seg.length = 1.85f;  // ends 0.05 before the dilated box (which starts at x = −0.1)
    EXPECT_FALSE(e.meets(seg, 0.0f));
    EXPECT_TRUE(e.meets(seg, 0.06f));  // its extension reaches in
    seg.triangle = kNoTriangle;        // escaping: no end
    EXPECT_TRUE(e.meets(seg, 0.0f));
    seg.direction = Vec3f(-1, 0, 0);   // pointing away
    EXPECT_FALSE(e.meets(seg, 0.0f));
    EXPECT_TRUE(Envelope::everything().meets(seg, 0.0f));
    EXPECT_NEAR(envelopeMargin(true, 0.1f, 0.0f), (1 + std::sqrt(2.0f)) * 0.1f, 1e-3f);
}
