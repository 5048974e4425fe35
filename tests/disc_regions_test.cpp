// Own surfaces, the disc pattern and disc regions (docs/design.md §5): heights on flat and curved
// surfaces, pattern moments, determinism across thread counts, and per-frame updates that equal a
// from-scratch computation.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>
#include <cstring>

#include "estimate/disc_regions.h"
#include "estimate/own_surface.h"
#include "estimate/own_surface_tree.h"
#include "scene/animation.h"
#include "scene/gltf_loader.h"
#include "scene/mesh_refinement.h"
#include "scene/mesh_topology.h"
#include "test_support.h"

using namespace qsgi;

namespace {
OwnSurface ownSurfaceOf(const Scene& scene, uint32_t v, float radius) {
    const MeshTopology topology(scene.positions, scene.triangles);
    OwnSurfaceScratch scratch;
    return findOwnSurface(v, scene, topology, scene.frontFaceNormals(), radius, scratch);
}

uint32_t nearestVertex(const Scene& scene, const Vec3f& worldPoint) {
    uint32_t best = 0;
    float bestD = 1e30f;
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        const Vec3f d = Vec3f(Vec3d(scene.positions[v]) + scene.worldOrigin) - worldPoint;
        if (dot(d, d) < bestD) bestD = dot(d, d), best = v;
    }
    return best;
}
}  // namespace

// The half-turn symmetry makes the first moments of the whole pattern vanish; the cell areas sum
// to π; every cell centre maps back to its own cell.
TEST(DiscPattern, CellsTileTheUnitDiscSymmetrically) {
    double area = 0, mx = 0, my = 0, mxx = 0, myy = 0;
    for (int c = 0; c < kDiscCells; ++c) {
        const CellMoments& m = discCellMoments(c);
        EXPECT_NEAR(m.m0, M_PI / kDiscCells, 1e-12);
        area += m.m0, mx += m.mx, my += m.my, mxx += m.mxx, myy += m.myy;
        double x, y;
        discCellCentre(c, x, y);
        EXPECT_EQ(discCellOf(x, y), c);
    }
    EXPECT_NEAR(area, M_PI, 1e-12);
    EXPECT_NEAR(mx, 0, 1e-12);
    EXPECT_NEAR(my, 0, 1e-12);
    EXPECT_NEAR(mxx, M_PI / 4, 1e-12);  // ∫x² over the unit disc
    EXPECT_NEAR(myy, M_PI / 4, 1e-12);
    std::array<double, kDiscRings> whole, half;
    whole.fill(1.0);
    half.fill(0.5);
    EXPECT_NEAR(discAreaWithin(whole, 0.5), M_PI * 0.25, 1e-12);
    EXPECT_NEAR(discAreaWithin(half, 1.0), M_PI * 0.5, 1e-12);
}

// Flat: both heights are the scene epsilon. Inside a sphere of radius R the surface rises toward
// the centre: ε⁺ is the sagitta of the clipped cap, R − sqrt(R² − r²) (up to the chords of the
// tessellation, which lie inside the sphere); outside, ε⁻ is. A light panel 1 cm under a
// ceiling is another object and never raises the ceiling's ε⁺.
TEST(OwnSurface, HeightsAreZeroOnFlatSurfacesAndTheSagittaOnCurvedOnes) {
    const float r = 0.1f;
    const Scene plane = testscenes::plane(1.0f, 32, Vec3f(0.5f));
    const OwnSurface flat = ownSurfaceOf(plane, nearestVertex(plane, Vec3f(0, 0, 0)), r);
    EXPECT_FALSE(flat.empty);
    EXPECT_FLOAT_EQ(flat.epsAbove, plane.sceneEpsilon());
    EXPECT_FLOAT_EQ(flat.epsBelow, plane.sceneEpsilon());

    const double sagitta = 1.0 - std::sqrt(1.0 - double(r) * r);
    for (bool inward : {true, false}) {
        const Scene sphere = testscenes::closedSphere(1.0f, 5, Vec3f(0.5f), inward);
        const OwnSurface s = ownSurfaceOf(sphere, 0, r);
        const double rising = inward ? s.epsAbove : s.epsBelow, other = inward ? s.epsBelow : s.epsAbove;
        EXPECT_NEAR(rising, sagitta, 0.1 * sagitta) << (inward ? "inside" : "outside");
        EXPECT_LT(other, 1e-5) << (inward ? "inside" : "outside");
    }

    Warnings w;
    const Scene cornell = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
    const OwnSurface ceiling = ownSurfaceOf(cornell, nearestVertex(cornell, Vec3f(0, 2, 0)), 0.05f);
    EXPECT_FALSE(ceiling.empty);
    EXPECT_LT(ceiling.epsAbove, 1e-4f) << "the light panel 1 mm below must not widen the ceiling's band";
}

// ε⁺ is a whole number of scene epsilons: on a tilted plane, whose corners lie a rounding error
// above or below it, every vertex has exactly one (the walk and the tree agree), while inside a
// sphere the sagitta is kept to half an epsilon.
TEST(OwnSurface, RisesCountInWholeSceneEpsilons) {
    const Transform tilt = Transform::fromTRS(Vec3d(0.3, 0.2, -0.1), {0.2, 0.3, 0.1, 0.927362}, Vec3d(1.0));
    const Scene floor = testscenes::tiledFloor(2, 16, tilt, Vec3f(0.5f));
    const double eps = floor.sceneEpsilon();
    const MeshTopology topology(floor.positions, floor.triangles);
    const std::vector<Vec3f> frontNormals = floor.frontFaceNormals();
    const OwnSurfaceTree tree(floor, frontNormals, topology);
    OwnSurfaceScratch scratch;
    size_t checked = 0, proved = 0;
    double largestNoise = 0;
    for (uint32_t v = 0; v < 4 * 17 * 17; ++v) {  // the floor's vertices, 2 x 2 tiles (the box's come after)
        OwnSurfaceQuery walk;
        walk.depthBelow = false;
        OwnSurfaceQuery quick = walk;
        quick.tree = &tree;
        const OwnSurface a = findOwnSurface(v, floor, topology, frontNormals, 0.03f, scratch, walk);
        const OwnSurface b = findOwnSurface(v, floor, topology, frontNormals, 0.03f, scratch, quick);
        const OwnSurface full = findOwnSurface(v, floor, topology, frontNormals, 0.03f, scratch);
        if (a.empty) continue;
        ASSERT_EQ(a.epsAbove, float(eps)) << "vertex " << v;
        ASSERT_EQ(b.epsAbove, a.epsAbove) << "vertex " << v;
        ASSERT_EQ(full.epsAbove, a.epsAbove) << "vertex " << v;
        largestNoise = std::max(largestNoise, double(full.epsBelow) - eps);
        ++checked;
        proved += b.provedByTree;
    }
    EXPECT_GT(checked, 400u);
    EXPECT_GT(proved, checked * 9 / 10);
    // The tilt is real: depths below the plane are rounding, not zero, and far under an epsilon.
    EXPECT_GT(largestNoise, 0.0);
    EXPECT_LT(largestNoise, 0.25 * eps);

    const Scene inside = testscenes::closedSphere(1.0f, 5, Vec3f(0.5f), true);
    const OwnSurface cap = ownSurfaceOf(inside, 0, 0.1f);
    const double e = inside.sceneEpsilon();
    const double steps = (double(cap.epsAbove) - e) / e;
    EXPECT_NEAR(steps, std::round(steps), 1e-3) << "a whole number of epsilons";
}

// The own-surface shortcut (OwnSurfaceTree) spares the walk, never changes an answer: every start
// point, ε⁺ and disc equals the one found by walking every own surface whole — on dense meshes
// (data/cornell refined to 2.5 cm at frame 30, its block turned; a tiled floor, flat and tilted)
// and on curved ones (data/walker, data/tree, inside and outside a sphere); DETP's regions (no
// coverage) on every case, and on data/cornell unrefined at r = 0.05.
TEST(OwnSurface, TheTreeShortcutChangesNoStartPointOrDisc) {
    struct Case {
        std::string name;
        Scene scene;
        float radius;
        enum { Most, Some, None } proved;  // how many vertices the tree should prove
    };
    std::vector<Case> cases;
    {
        Warnings w;
        Scene cornell = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
        const Animation animation =
            Animation::fromTransformFile((sourceDir() / "data/cornell/animation.json").string(), cornell);
        // Under the sanitizers to 5 cm (a quarter of the vertices; the reference walk is the
        // test's cost): the same meshes, the same moved block, the same questions.
        const double edge = kSanitized ? 0.05 : 0.025;
        refineMesh(cornell, edge);
        cornell.markDynamic(animation.movedNodes());
        sweepAnimationBounds(cornell, animation);
        cornell.applyPose(animation.localsAt(30));
        cases.push_back({"cornell refined to " + std::to_string(edge) + ", frame 30", std::move(cornell), 0.05f, Case::Most});
    }
    cases.push_back({"tiled floor", testscenes::tiledFloor(3, 32, Transform(), Vec3f(0.5f)), 0.03f, Case::Most});
    cases.push_back({"tilted tiled floor",
                     testscenes::tiledFloor(3, 32, Transform::fromTRS(Vec3d(0.0), {0.1, 0.2, 0.05, 0.972111}, Vec3d(1.0)),
                                            Vec3f(0.5f)),
                     0.03f, Case::Most});
    for (const char* name : {"walker", "tree"}) {
        Warnings w;
        cases.push_back({name, loadGltfScene((sourceDir() / "data" / name / (std::string(name) + ".gltf")).string(), w), 0.05f,
                         Case::Some});
    }
    // Inside, the surface rises all round (the walk always runs); outside, it falls away.
    cases.push_back({"inside a sphere", testscenes::closedSphere(1.0f, 5, Vec3f(0.5f), true), 0.1f, Case::None});
    cases.push_back({"outside a sphere", testscenes::closedSphere(1.0f, 5, Vec3f(0.5f), false), 0.1f, Case::Most});
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        EmbreeDevice device;
        const SceneBvh bvh(device, c.scene);
        DiscRegions quick(c.radius, false), reference(c.radius, false);
        quick.setTreeUse(DiscRegions::TreeUse::Always);  // coarse scenes too: the tree's answers against the walk's
        reference.useOwnSurfaceShortcut(false);
        quick.computeAll(c.scene, bvh);
        reference.computeAll(c.scene, bvh);
        for (uint32_t v = 0; v < c.scene.vertexCount(); ++v) {
            ASSERT_TRUE(quick[v] == reference[v]) << "vertex " << v << ": eps+ " << quick[v].epsAbove << " against "
                                                  << reference[v].epsAbove << ", area " << quick[v].reachableArea << " against "
                                                  << reference[v].reachableArea;
        }
        EXPECT_EQ(reference.lastWork().ownSurfacesProved, 0u);
        const uint64_t proved = quick.lastWork().ownSurfacesProved;
        std::printf("%s: %zu vertices, %llu own surfaces proved by the tree\n", c.name.c_str(), c.scene.vertexCount(),
                    static_cast<unsigned long long>(proved));
        switch (c.proved) {
            case Case::Most: EXPECT_GT(proved, c.scene.vertexCount() * 9 / 10); break;
            case Case::Some: EXPECT_GT(proved, c.scene.vertexCount() / 2); break;
            case Case::None: EXPECT_EQ(proved, 0u); break;
        }
    }
    // DETP's regions (no coverage) read ε⁺ through the same search.
    Warnings w;
    const Scene cornell = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
    EmbreeDevice device;
    const SceneBvh bvh(device, cornell);
    DiscRegions quick(0.05f, false), reference(0.05f, false);
    quick.setTreeUse(DiscRegions::TreeUse::Always);
    reference.useOwnSurfaceShortcut(false);
    quick.computeAll(cornell, bvh);
    reference.computeAll(cornell, bvh);
    for (size_t v = 0; v < cornell.vertexCount(); ++v) ASSERT_TRUE(quick[v] == reference[v]) << "DETP, vertex " << v;
    EXPECT_GT(quick.lastWork().ownSurfacesProved, cornell.vertexCount() / 2);
}

// Same bytes for one thread and for two: each vertex's regions depend on the geometry alone.
TEST(DiscRegions, AreIdenticalForAnyThreadCount) {
    Warnings w;
    const Scene scene = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
    EmbreeDevice device;
    const SceneBvh bvh(device, scene);
    std::vector<DiscRegions> results;
    for (size_t threads : {1, 2}) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        results.emplace_back(0.05f, true);
        results.back().computeAll(scene, bvh);
    }
    for (size_t v = 0; v < scene.vertexCount(); ++v) ASSERT_TRUE(results[0][v] == results[1][v]) << "vertex " << v;
    // Cornell has inside edges everywhere along its walls: some vertices see part of their disc only.
    size_t partial = 0;
    for (size_t v = 0; v < scene.vertexCount(); ++v) partial += results[0][v].reachable.count() < kDiscCells;
    EXPECT_GT(partial, 1000u);
    EXPECT_EQ(results[0].fallbackVertices(), 0u);
}

namespace {

// The scenes the shortcut is tested on, with their radii: cornell's flat walls and inside edges,
// the tree's leaves and trunk, and a floor with a rug on it (testscenes::slabOnFloor, 0.6 wide)
// 20 and 2 scene epsilons high: the floor's rays run one epsilon up, so they meet the rug's sides
// however low it is.
struct ShortcutScene {
    const char* name;
    float radius;
    float rugEpsilons = 0;  // 0: the glTF file `name`
};
const ShortcutScene kShortcutScenes[] = {{"data/cornell/cornell.gltf", 0.05f},
                                         {"data/tree/tree.gltf", 0.2f},
                                         {"rug 20 epsilons high", 0.1f, 20},
                                         {"rug 2 epsilons high", 0.1f, 2}};
constexpr int kRugFloorCells = 24;
constexpr float kRugHalf = 0.3f;

Scene shortcutScene(const ShortcutScene& c) {
    // The rug's scene epsilon: 10^-6 of the floor's diagonal, 2√2.
    if (c.rugEpsilons > 0) return testscenes::slabOnFloor(kRugFloorCells, kRugHalf, c.rugEpsilons * 2.828427e-6f, Vec3f(0.5f));
    Warnings w;
    return loadGltfScene((sourceDir() / c.name).string(), w);
}

}  // namespace

// Each cell that is not mixed is reachable exactly when the single ray from the disc's start to
// its lifted centre is clear (discPointReachable asks the whole scene, one ray at a time): the
// packets and the shortcut that skips the static rays where no static triangle rises to their
// height must give that answer. Every third vertex.
TEST(DiscRegions, UniformCellsAgreeWithASingleRayToTheirCentre) {
    const DiscPatternPoints& points = discPatternPoints();
    for (const ShortcutScene& c : kShortcutScenes) {
        SCOPED_TRACE(c.name);
        const float radius = c.radius;
        const Scene scene = shortcutScene(c);
        EmbreeDevice device;
        const SceneBvh bvh(device, scene);
        DiscRegions regions(radius, false);
        regions.computeAll(scene, bvh);
        uint64_t cells = 0, reachable = 0;
        for (uint32_t v = 0; v < scene.vertexCount(); v += 3) {
            const VertexDisc& disc = regions[v];
            if (disc.fallback) continue;
            for (int c = 0; c < kDiscCells; ++c) {
                if (disc.mixed.test(size_t(c))) continue;
                const bool clear = discPointReachable(disc, scene.positions[v], scene.normals[v], radius,
                                                      points.centres[size_t(c)].x, points.centres[size_t(c)].y, bvh);
                ASSERT_EQ(disc.reachable.test(size_t(c)), clear) << "vertex " << v << " cell " << c;
                ++cells;
                reachable += clear;
            }
        }
        // Both answers occur: the check is not one-sided.
        EXPECT_GT(reachable, cells / 2);
        EXPECT_LT(reachable, cells);
        const DiscRegions::Work& work = regions.lastWork();
        EXPECT_GT(work.rays, 0u);
        EXPECT_GT(work.staticRaysSkipped, 0u);
        if (c.rugEpsilons == 0) continue;
        // The shortcut takes exactly the floor vertices whose ball (r and a hair) misses the rug:
        // the rug's corners and the floor vertices within r of its footprint trace their rays.
        // The rug's own vertices may go either way.
        auto footprintDistance = [&](const Vec3f& p) {
            // Floor coordinates: the scene is re-centred, and its first vertex is the corner (−1, 0, 1).
            const Vec3f q = p - scene.positions[0] + Vec3f(-1, 0, 1);
            const float dx = std::max(std::abs(q.x) - kRugHalf, 0.0f), dz = std::max(std::abs(q.z) - kRugHalf, 0.0f);
            return std::sqrt(dx * dx + dz * dz);
        };
        const uint32_t floorVertices = (kRugFloorCells + 1) * (kRugFloorCells + 1);
        uint64_t surelyFar = 0, maybeFar = 0;
        for (uint32_t v = 0; v < floorVertices; ++v) {
            surelyFar += footprintDistance(scene.positions[v]) > radius * 1.001f;
            maybeFar += footprintDistance(scene.positions[v]) > radius * 0.999f;
        }
        EXPECT_GE(work.staticRaysSkipped, surelyFar);
        EXPECT_LE(work.staticRaysSkipped, maybeFar + (scene.vertexCount() - floorVertices));
        EXPECT_GT(surelyFar, 300u);
    }
}

// The shortcut spares rays, never changes an answer: every disc (masks, mixed shares, start,
// areas, coverage) equals the one found with every static ray traced and every own surface
// walked, with and without coverage, on every scene above — with the static question put to
// Embree's point query and to OwnSurfaceTree.
TEST(DiscRegions, TheStaticShortcutChangesNoDisc) {
    for (const ShortcutScene& c : kShortcutScenes) {
        const Scene scene = shortcutScene(c);
        EmbreeDevice device;
        const SceneBvh bvh(device, scene);
        for (bool coverage : {false, true}) {
            // The reference traces every ray and walks every surface: it does not depend on how
            // the quick one asks its static question, so both askers are held to one reference.
            DiscRegions reference(c.radius, coverage);
            reference.useStaticShortcut(false);
            reference.useOwnSurfaceShortcut(false);
            reference.computeAll(scene, bvh);
            for (bool tree : {false, true}) {
                SCOPED_TRACE(std::string(c.name) + (coverage ? ", with coverage" : "") +
                             (tree ? ", asking OwnSurfaceTree" : ", asking Embree's point query"));
                DiscRegions quick(c.radius, coverage);
                quick.setTreeUse(tree ? DiscRegions::TreeUse::Always : DiscRegions::TreeUse::Never);
                quick.computeAll(scene, bvh);
                for (size_t v = 0; v < scene.vertexCount(); ++v) ASSERT_TRUE(quick[v] == reference[v]) << "vertex " << v;
                EXPECT_GT(quick.lastWork().staticRaysSkipped, 0u);
                EXPECT_EQ(reference.lastWork().staticRaysSkipped, 0u);
                EXPECT_LT(quick.lastWork().rays, reference.lastWork().rays);
            }
        }
    }
}

// The block of data/cornell slides across the floor. Regions updated per frame (the moved
// vertices and the static vertices whose test region the block's old or new bounds touch) must
// equal regions computed from scratch for that frame, and far fewer vertices are recomputed.
TEST(DiscRegions, PerFrameUpdatesEqualAFromScratchComputation) {
    Warnings w;
    Scene scene = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
    const Animation animation = Animation::fromTransformFile((sourceDir() / "data/cornell/animation.json").string(), scene);
    scene.markDynamic(animation.movedNodes());
    sweepAnimationBounds(scene, animation);
    EmbreeDevice device;
    scene.applyPose(animation.localsAt(0));
    DiscRegions updated(0.05f, true);
    {
        const SceneBvh bvh(device, scene);
        updated.computeAll(scene, bvh);
    }
    for (int frame : {1, 2, 30}) {
        std::vector<uint32_t> moved;
        std::vector<Bounds3f> movedBounds;
        scene.applyPose(animation.localsAt(frame), &moved, &movedBounds);
        ASSERT_FALSE(moved.empty());
        std::vector<uint8_t> vertexMoved(scene.vertexCount(), 0);
        for (uint32_t i : moved)
            std::fill_n(vertexMoved.begin() + scene.instances[i].firstVertex, scene.instances[i].vertexCount, 1);
        const SceneBvh bvh(device, scene);
        const std::vector<uint32_t> touched = updated.touchedBy(scene, movedBounds, vertexMoved);
        updated.recompute(scene, bvh, touched);
        // The reference traces every static ray: the update's shortcut and kept answers must
        // agree with it.
        DiscRegions fresh(0.05f, true);
        fresh.useStaticShortcut(false);
        fresh.computeAll(scene, bvh);
        for (size_t v = 0; v < scene.vertexCount(); ++v)
            ASSERT_TRUE(updated[v] == fresh[v]) << "frame " << frame << " vertex " << v;
        EXPECT_LT(touched.size(), scene.vertexCount() / 4) << "frame " << frame;
        std::printf("cornell frame %d: %zu of %zu vertices' disc regions recomputed\n", frame, touched.size(),
                    scene.vertexCount());
    }
    // Frames 2 and 30 asked the static BVH only where frame 1 had not: the kept answers served.
    EXPECT_GT(updated.keptAnswerBytes(), 0u);
}
