// Accuracy where the eye looks (issue 47, estimate/surface_accuracy.h): a frame's irradiance
// interpolated across its triangles at a surface reference's points, by band. On a block standing
// on a floor, whose bands follow from its geometry in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

#include "estimate/surface_accuracy.h"
#include "scene/mesh_refinement.h"
#include "test_support.h"

using namespace qsgi;

namespace {
constexpr float kFloorHalf = 1.0f, kBlockHalf = 0.25f, kBlockHeight = 0.5f, kWidth = 0.05f;

Scene blockScene() { return testscenes::blockOnFloor(16, kFloorHalf, kBlockHalf, kBlockHeight, 2, Vec3f(0.5f)); }

// Points uniformly by area over the scene's triangles (as reference.py draws them), at world
// positions; irradiance `field` of the world position.
template <typename Field>
std::vector<SurfacePoint> drawPoints(const Scene& scene, size_t count, uint32_t seed, Field&& field) {
    std::vector<double> cdf;
    double total = 0;
    for (uint32_t t = 0; t < scene.triangleCount(); ++t) cdf.push_back(total += scene.triangleArea(t));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<SurfacePoint> points(count);
    for (SurfacePoint& p : points) {
        p.triangle = uint32_t(std::lower_bound(cdf.begin(), cdf.end(), u(rng) * total) - cdf.begin());
        p.triangle = std::min(p.triangle, uint32_t(scene.triangleCount() - 1));
        const double r1 = std::sqrt(u(rng)), r2 = u(rng);
        p.b1 = float(r1 * (1 - r2));
        p.b2 = float(r1 * r2);
        const Triangle& T = scene.triangles[p.triangle];
        const double b1 = p.b1, b2 = p.b2;
        const Vec3d at = Vec3d(scene.positions[T.v[0]]) * (1 - b1 - b2) + Vec3d(scene.positions[T.v[1]]) * b1 +
                         Vec3d(scene.positions[T.v[2]]) * b2;
        p.position = Vec3f(at);
        p.normal = frontFaceNormal(scene.positions, scene.normals, T);
        p.irradiance = field(at + scene.worldOrigin);
    }
    return points;
}

Vec3f linearField(const Vec3d& w) { return Vec3f(float(1 + 2 * w.x), float(3 + w.z), float(2 + w.x - w.y)); }

// The band a world point of the block scene lies in, from its geometry; -1 within 10⁻⁴ of a
// threshold (rounding may put it either side).
int expectedBand(const Vec3d& w) {
    const double h = kBlockHalf, H = kBlockHeight, r = kWidth;
    auto decide = [&](double toOther, double toEdge) {
        if (std::abs(toOther - r) < 1e-4 || std::abs(toEdge - r) < 1e-4) return -1;
        if (toOther <= r) return int(SurfaceBand::Contact);
        return toEdge <= r ? int(SurfaceBand::Edge) : int(SurfaceBand::Interior);
    };
    const double ax = std::abs(w.x), az = std::abs(w.z);
    if (std::abs(w.y) < 1e-6) {  // the floor: the block's sides rise from its foot, the floor's border
        const double dx = std::max(0.0, ax - h), dz = std::max(0.0, az - h);
        const double toBlock = (dx > 0 || dz > 0) ? std::hypot(dx, dz) : std::min(h - std::max(ax, az), H);
        // The block's bottom edges are borders too, but nearer another surface than the width.
        return decide(toBlock, std::min(kFloorHalf - std::max(ax, az), toBlock));
    }
    if (std::abs(w.y - H) < 1e-6) return decide(H, h - std::max(ax, az));  // the top: its crease with the sides
    // A side: the floor below it; the creases at its vertical corners and at the top.
    const double along = std::abs(ax - h) < 1e-6 ? az : ax;
    return decide(w.y, std::min({h - along, H - w.y, w.y}));
}
}  // namespace

TEST(SurfaceAccuracy, BandsFollowTheGeometryALinearFieldIsExactAndTheReferencesNoiseComesOut) {
    const Scene scene = blockScene();
    std::vector<Vec3f> linear(scene.vertexCount());
    for (uint32_t v = 0; v < scene.vertexCount(); ++v) linear[v] = linearField(Vec3d(scene.positions[v]) + scene.worldOrigin);
    std::vector<SurfacePoint> points = drawPoints(scene, 20000, 5, linearField);

    const std::vector<PointOnMesh> located = locateOnMesh(scene.positions, scene.normals, scene.triangles, points);
    const std::vector<SurfaceBand> bands = surfaceBands(scene.positions, scene.normals, scene.triangles, located, kWidth);
    size_t decided = 0, counts[3] = {0, 0, 0};
    for (size_t i = 0; i < points.size(); ++i) {
        const int expected = expectedBand(Vec3d(points[i].position) + scene.worldOrigin);
        if (expected < 0) continue;
        ++decided;
        ++counts[int(bands[i])];
        ASSERT_EQ(int(bands[i]), expected) << "point " << i << " at world " << (Vec3d(points[i].position) + scene.worldOrigin).x
                                           << ", " << (Vec3d(points[i].position) + scene.worldOrigin).y << ", "
                                           << (Vec3d(points[i].position) + scene.worldOrigin).z;
    }
    EXPECT_GT(decided, 19900u);
    for (size_t k = 0; k < 3; ++k) EXPECT_GT(counts[k], 500u) << "band " << k;

    // A field linear on every triangle is interpolated exactly (float storage: 10⁻⁶).
    points[0].hidden = points[1].hidden = true;
    points[0].irradiance = points[1].irradiance = Vec3f(1e6f);  // hidden: counts for nothing
    const SurfaceAccuracyReport exact = compareOverSurface(scene.positions, scene.normals, scene.triangles, linear, points, kWidth);
    EXPECT_EQ(exact.hidden, 2u);
    EXPECT_EQ(exact.all.points, points.size() - 2);
    EXPECT_EQ(exact.contact.points + exact.edge.points + exact.interior.points, exact.all.points);
    for (const SurfaceErrorStats* s : {&exact.all, &exact.contact, &exact.edge, &exact.interior}) EXPECT_LT(s->relativeRms, 1e-6);

    // An error d everywhere against a reference whose standard error is s: d, and √(d² − s²) without it.
    const float d = 0.2f, s = 0.1f;
    std::vector<Vec3f> off = linear;
    for (Vec3f& v : off) v = v + Vec3f(d);
    for (SurfacePoint& p : points) p.standardError = Vec3f(s);
    const SurfaceAccuracyReport noisy = compareOverSurface(scene.positions, scene.normals, scene.triangles, off, points, kWidth);
    double scale = 0;
    for (size_t i = 2; i < points.size(); ++i) scale += (std::fabs(points[i].irradiance.x) + std::fabs(points[i].irradiance.y) +
                                                         std::fabs(points[i].irradiance.z)) / 3;
    scale /= double(points.size() - 2);
    EXPECT_NEAR(noisy.all.relativeRms, d / scale, 1e-5);
    EXPECT_NEAR(noisy.all.relativeBias, d / scale, 1e-5);
    EXPECT_NEAR(noisy.all.referenceNoise, s / scale, 1e-6);
    EXPECT_NEAR(noisy.all.withoutNoise, std::sqrt(d * d - s * s) / scale, 1e-5);
}

// Points are found on the frame's mesh by position, so a refined frame (--subdivide) is scored at
// the same places: a field linear on the refined triangles is exact there, each point falls on the
// refined triangle inside its own, and the bands are those of the unrefined mesh.
TEST(SurfaceAccuracy, ARefinedFrameIsScoredAtTheSamePlaces) {
    const Scene coarse = blockScene();
    Scene fine = blockScene();
    refineMesh(fine, 0.04);
    ASSERT_GT(fine.triangleCount(), 4 * coarse.triangleCount());
    const std::vector<SurfacePoint> points = drawPoints(coarse, 5000, 9, linearField);
    std::vector<Vec3f> linear(fine.vertexCount());
    for (uint32_t v = 0; v < fine.vertexCount(); ++v) linear[v] = linearField(Vec3d(fine.positions[v]) + fine.worldOrigin);
    const SurfaceAccuracyReport r = compareOverSurface(fine.positions, fine.normals, fine.triangles, linear, points, kWidth);
    EXPECT_EQ(r.all.points, points.size());
    EXPECT_LT(r.all.relativeRms, 1e-6);
    const std::vector<PointOnMesh> onCoarse = locateOnMesh(coarse.positions, coarse.normals, coarse.triangles, points);
    const std::vector<PointOnMesh> onFine = locateOnMesh(fine.positions, fine.normals, fine.triangles, points);
    const std::vector<SurfaceBand> coarseBands = surfaceBands(coarse.positions, coarse.normals, coarse.triangles, onCoarse, kWidth);
    const std::vector<SurfaceBand> fineBands = surfaceBands(fine.positions, fine.normals, fine.triangles, onFine, kWidth);
    size_t same = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        same += coarseBands[i] == fineBands[i];
        // Unrefined, the point is found on the triangle it was drawn on, at its own barycentrics.
        EXPECT_NEAR(onCoarse[i].b1 + onCoarse[i].b2, double(points[i].b1) + double(points[i].b2), 1e-4) << "point " << i;
    }
    // Only points within rounding of a band's edge may differ (float midpoints).
    EXPECT_GE(same, points.size() - 5);
}

TEST(SurfaceAccuracy, PointsDrawnOnAnotherSceneOrPoseAreRefused) {
    const Scene scene = blockScene();
    std::vector<SurfacePoint> points = drawPoints(scene, 100, 7, linearField);
    EXPECT_NO_THROW(locateOnMesh(scene.positions, scene.normals, scene.triangles, points));
    points[5].position = points[5].position + points[5].normal * 0.01f;  // 1 cm off the surface, 2 m scene
    EXPECT_THROW(locateOnMesh(scene.positions, scene.normals, scene.triangles, points), std::invalid_argument);
}
