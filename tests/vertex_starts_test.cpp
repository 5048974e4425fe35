// Where the second pass's rays start (issue 56, lib/estimate/vertex_starts.h): at the vertex, a float
// error up, whatever the photon radius and whatever else the scene holds. Direct light under a
// uniform sky is then π × the sky share of the vertex-normal hemisphere seen from the vertex —
// on a concave crease, on a smooth low-poly icosahedron, under a plate lying a hair over a floor.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "estimate/final_gather.h"
#include "pipeline/frame_solver.h"
#include "pipeline/render_settings.h"
#include "scene/gltf_loader.h"
#include "scene/mesh_topology.h"
#include "test_support.h"

using namespace qsgi;

namespace {

std::shared_ptr<const EnvironmentLight> uniformSky(float radiance) {
    return std::make_shared<const EnvironmentLight>(EnvironmentLight::uniform(Vec3f(radiance)));
}

// Direct light alone: black surfaces send nothing on, so E = D under exact direct light with
// no gather.
std::vector<Vec3f> directLightOf(Scene& scene, float radius, uint32_t samples, uint64_t seed = 3) {
    const EmbreeDevice device;
    FrameSolverSettings s;
    s.estimator.kind = EstimatorKind::Detp;
    s.estimator.radius = radius;
    s.trace.photons = 2000;
    s.trace.seed = seed;
    s.lighting.direct = DirectLighting::Exact;
    s.lighting.directSamples = samples;
    s.lighting.gatherRays = 0;
    s.update.fullRecompute = true;
    FrameSolver solver(scene, device, s);
    return solver.solve(scene.restPose()).radiosity.irradiance;
}

// A rectangle { corner + a·u + b·w : a, b in [0, 1] } with u ⟂ w.
struct Rectangle {
    Vec3d corner, u, w;
    // Whether the ray o + t d, t > 0, meets it (double precision, independent of Embree).
    bool meets(const Vec3d& o, const Vec3d& d) const {
        const Vec3d n = cross(u, w);
        const double den = dot(d, n);
        if (den == 0) return false;
        const double t = dot(corner - o, n) / den;
        if (!(t > 0)) return false;
        const Vec3d q = o + d * t - corner;
        const double a = dot(q, u) / dot(u, u), b = dot(q, w) / dot(w, w);
        return a >= 0 && a <= 1 && b >= 0 && b <= 1;
    }
};

// The cosine-weighted share of the hemisphere about n from which a ray leaving `from` meets none of
// `blockers`: a midpoint rule over grid × grid cells of the cosine-distributed square (its error is
// at most the share of cells the blocked region's edge crosses, about 2/grid).
double skyShare(const Vec3d& from, const Vec3d& n, const std::vector<Rectangle>& blockers, int grid) {
    Vec3d t, b;
    orthonormalBasis(n, t, b);
    long clear = 0;
    for (int i = 0; i < grid; ++i)
        for (int j = 0; j < grid; ++j) {
            const double u0 = (i + 0.5) / grid, u1 = (j + 0.5) / grid;
            const double r = std::sqrt(u0), phi = 2 * M_PI * u1;
            const Vec3d d = t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * std::sqrt(1 - u0);
            bool blocked = false;
            for (const Rectangle& rect : blockers) blocked = blocked || rect.meets(from, d);
            clear += !blocked;
        }
    return double(clear) / double(grid) / double(grid);
}

Vec3d worldOf(const Scene& scene, const Vec3f& p) { return Vec3d(p) + scene.worldOrigin; }

}  // namespace

// The first test: two quads at 90° (testscenes::creasedSheet, 2 cells a side: coarse),
// black, under a sky of radiance 1. At every vertex — on the crease with its 45° normal (welded) or
// its face's (split), on the borders, at the corners — D equals π × the sky share seen from the
// vertex, found here by an independent ray cast against the two rectangles from the vertex (10⁻⁹ m
// along its normal; and out of the wall where it stands at the foot of one) — and, at the sheet's
// borders, where that differs from what the surface beside the vertex sees, between the two. The sky's S cosine-distributed rays estimate the share with a
// standard error of at most √(s(1−s)/S) (Sobol points do better); the quadrature's own error is at
// most 2/grid. And D is the same to the bit for any photon radius: the rays no longer start from a
// point lifted with r.
TEST(VertexStarts, ACreaseUnderASkyReceivesPiTimesItsExactSkyShareWhateverTheRadius) {
    constexpr uint32_t S = 65536;
    constexpr int kGrid = 1024;
    const std::vector<Rectangle> sheet = {{{-1, 0, 0}, {2, 0, 0}, {0, 0, 1}},   // floor y = 0, front +y
                                          {{-1, 0, 0}, {2, 0, 0}, {0, 1, 0}}};  // wall z = 0, front +z
    const Vec3d fronts[2] = {{0, 1, 0}, {0, 0, 1}};
    for (const bool welded : {true, false}) {
        SCOPED_TRACE(welded ? "welded (45° normals on the crease)" : "split (face normals)");
        Scene scene = testscenes::creasedSheet(2, welded, Vec3f(0.0f));
        scene.environment = uniformSky(1.0f);
        std::vector<Vec3f> first;
        for (const float radius : {0.01f, 0.1f, 0.5f}) {
            const std::vector<Vec3f> D = directLightOf(scene, radius, S);
            if (first.empty()) {
                first = D;
                double worst = 0;
                for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
                    // From the vertex itself, 10⁻⁹ m along its normal, and 10⁻⁸ m out of the front
                    // of a wall standing on it (a split crease's other side, 90° from the normal);
                    // and from the surface beside it, 10⁻⁷ m toward the middle of the L and
                    // 10⁻¹² m up. The two agree but at the sheet's borders, where the vertex ends
                    // the surface: there D lies between them.
                    const Vec3d p = worldOf(scene, scene.positions[v]), n = normalize(Vec3d(scene.normals[v]));
                    Vec3d atVertex = p + n * 1e-9;
                    for (int k = 0; k < 2; ++k)
                        if (dot(p - sheet[k].corner, fronts[k]) == 0 && dot(fronts[k], n) < 0.125) atVertex += fronts[k] * 1e-8;
                    const Vec3d toMiddle = Vec3d(0, 0.5, 0.5) - p, along = toMiddle - n * dot(toMiddle, n);
                    const Vec3d beside = p + n * 1e-12 + (length(along) > 0 ? normalize(along) * 1e-7 : Vec3d(0.0));
                    const double s1 = skyShare(atVertex, n, sheet, kGrid), s2 = skyShare(beside, n, sheet, kGrid);
                    const double share = std::clamp(double(D[v].x) / M_PI, std::min(s1, s2), std::max(s1, s2));
                    const double tolerance = M_PI * (4 * std::sqrt(share * (1 - share) / S) + 2.0 / kGrid);
                    EXPECT_NEAR(D[v].x, M_PI * share, tolerance) << "vertex " << v << " at " << p.x << ", " << p.y << ", " << p.z
                                                                 << ": the vertex's share " << s1 << ", beside it " << s2;
                    worst = std::max(worst, std::abs(D[v].x - M_PI * share) / (M_PI * share));
                }
                std::printf("%s crease: %zu vertices, worst |D / (pi share) - 1| = %.4f\n", welded ? "welded" : "split",
                            scene.vertexCount(), worst);
            } else {
                ASSERT_EQ(D.size(), first.size());
                for (uint32_t v = 0; v < scene.vertexCount(); ++v)
                    ASSERT_EQ(std::memcmp(&D[v], &first[v], sizeof(Vec3f)), 0) << "vertex " << v << ", radius " << radius;
            }
        }
    }
}

// The documented convention (docs/method.md): a smooth-shaded low-poly mesh receives over the
// vertex-normal hemisphere seen from the vertex. On a convex icosahedron with radial normals
// every direction of that hemisphere reaches the sky: D = π L at every vertex, to float rounding
// — where a per-corner bake (Cycles') drops the directions below each face and reads 0.894 π.
TEST(VertexStarts, ASmoothIcosahedronUnderASkyReceivesPi) {
    Scene scene = testscenes::closedSphere(1.0f, 0, Vec3f(0.0f), false);
    ASSERT_EQ(scene.vertexCount(), 12u);
    scene.environment = uniformSky(1.0f);
    const std::vector<Vec3f> D = directLightOf(scene, defaultRadius(scene), 256);
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) {
        ASSERT_NEAR(dot(scene.normals[v], normalize(scene.positions[v] - Vec3f(Vec3d(0.0) - scene.worldOrigin))), 1.0f, 1e-6f);
        EXPECT_NEAR(D[v].x, M_PI, 256 * 0x1p-24 * M_PI) << "vertex " << v;
    }
}

// Adding a far quad enlarges the scene's diagonal 12-fold (and with it the default radius and the
// scene epsilon) and changes nothing the sheet's vertices see: their direct light under the sky,
// at the default radius of each scene, is the same within the estimate's own noise (4 standard
// errors of S cosine rays at the share found), and differs at all only where the start's float
// offset moved with the re-centred coordinates.
TEST(VertexStarts, AFarQuadLeavesAnObjectsDirectLightUnchanged) {
    constexpr uint32_t S = 4096;
    Scene alone = testscenes::creasedSheet(4, true, Vec3f(0.0f));
    Scene withFar = testscenes::creasedSheet(4, true, Vec3f(0.0f), 20.0f);
    alone.environment = withFar.environment = uniformSky(1.0f);
    ASSERT_GT(withFar.animationBounds.extent(), 8 * alone.animationBounds.extent());
    const std::vector<Vec3f> a = directLightOf(alone, defaultRadius(alone), S);
    const std::vector<Vec3f> b = directLightOf(withFar, defaultRadius(withFar), S);
    size_t differing = 0;
    for (uint32_t v = 0; v < alone.vertexCount(); ++v) {
        ASSERT_EQ(worldOf(alone, alone.positions[v]), worldOf(withFar, withFar.positions[v]));
        const double share = a[v].x / M_PI;
        EXPECT_NEAR(b[v].x, a[v].x, M_PI * 4 * std::sqrt(std::max(share * (1 - share), 1.0 / S) / S)) << "vertex " << v;
        differing += a[v].x != b[v].x;
    }
    std::printf("far quad: %zu of %zu sheet vertices' direct light differs at all\n", differing, alone.vertexCount());
}

// The plate test, with the plate's front toward the floor and away from it: a sheet
// 0.5 mm over a plate, under a sky. The plate's vertices under the sheet (2 cm or more inside
// its edge) read what reaches under it: the sky only through the 0.5 mm gap, at most the share
// of directions within atan(0.5/20) of the horizon, sin² of that = 6·10⁻⁴ of π. With a gather
// (albedo 0.5) they stay near 0 too, and they are covered — by back faces when the sheet faces
// up, by a front face lower than a quarter of their edge when it faces them.
TEST(VertexStarts, APlateAHairUnderASheetReadsWhatReachesUnderIt) {
    constexpr float kGap = 0.0005f, kSheetHalf = 0.25f;
    for (const bool facesUp : {true, false}) {
        SCOPED_TRACE(facesUp ? "sheet facing up" : "sheet facing the plate");
        Scene scene = testscenes::plateUnderSheet(0.5f, 20, kSheetHalf, 10, kGap, facesUp, Vec3f(0.5f));
        scene.environment = uniformSky(1.0f);
        const EmbreeDevice device;
        FrameSolverSettings s;
        s.estimator.kind = EstimatorKind::Detp;
        s.estimator.radius = defaultRadius(scene);
        s.trace.photons = 20000;
        s.lighting.direct = DirectLighting::Exact;
        s.lighting.directSamples = 256;
        s.lighting.gatherRays = 64;
        FrameSolver solver(scene, device, s);
        const std::vector<Vec3f> E = solver.solve(scene.restPose()).radiosity.irradiance;
        const std::vector<uint8_t> covered = solver.coveredVertices();
        size_t under = 0;
        double sum = 0;
        for (uint32_t v = 0; v < scene.instances[0].vertexCount; ++v) {
            const Vec3d p = worldOf(scene, scene.positions[v]);
            if (std::max(std::abs(p.x), std::abs(p.z)) > kSheetHalf - 0.02) continue;
            ++under;
            sum += E[v].x;
            EXPECT_LE(E[v].x, 0.01 * M_PI) << "plate vertex " << v << " at " << p.x << ", " << p.z;
            EXPECT_TRUE(covered[v]) << "plate vertex " << v;
        }
        ASSERT_GE(under, 25u);
        std::printf("%s: %zu plate vertices under the sheet, mean E %.5f W/m^2 (open plate: pi)\n",
                    facesUp ? "sheet up" : "sheet down", under, sum / double(under));
    }
}

// The start itself: within a few float offsets of the vertex on every scene, never lifted with r.
TEST(VertexStarts, StartsLieWithinAFewFloatErrorsOfTheirVertex) {
    Warnings w;
    const Scene cornell = loadGltfScene((sourceDir() / "data/cornell/cornell.gltf").string(), w);
    EmbreeDevice device;
    const SceneBvh bvh(device, cornell);
    VertexStarts starts;
    starts.computeAll(cornell, bvh);
    const MeshTopology topology(cornell.positions, cornell.triangles);
    const std::vector<Vec3f> front = cornell.frontFaceNormals();
    for (uint32_t v = 0; v < cornell.vertexCount(); ++v) {
        const VertexStart one = vertexRayStart(cornell, bvh, topology, front, v);
        ASSERT_EQ(one.point, starts.point(v)) << "vertex " << v;
        const double away = length(Vec3d(starts.point(v)) - Vec3d(cornell.positions[v]));
        ASSERT_GT(one.offset, 0.0f);
        ASSERT_LE(away, 21.0 * one.offset) << "vertex " << v;
        ASSERT_LE(one.offset, 1e-4 * cornell.animationBounds.extent()) << "vertex " << v;
    }
}
