// The camera and the radiosity view (docs/design.md §2, §7): pixel radiance is B/π interpolated over the
// hit triangle, background black.
#include <gtest/gtest.h>

#include "output/radiosity_image.h"
#include "scene/camera.h"
#include "test_support.h"
#include "trace/sampling.h"

using namespace qsgi;

TEST(Camera, CentreRayIsTheViewDirectionAndEdgesSpanTheFieldOfView) {
    const Camera c = lookAtCamera({0, 1, 4}, {0, 1, 0}, {0, 1, 0}, 0.7f);
    const Vec3f centre = cameraRay(c, 320, 240, 640, 480).direction;
    EXPECT_NEAR(dot(centre, Vec3f(0, 0, -1)), 1.0f, 1e-6f);
    const Vec3f top = cameraRay(c, 320, 0, 640, 480).direction;
    EXPECT_NEAR(std::acos(dot(top, centre)), 0.35f, 1e-5f);  // yfov / 2
    EXPECT_GT(top.y, 0.0f);                                     // image y runs down
    const Vec3f right = cameraRay(c, 640, 240, 640, 480).direction;
    EXPECT_GT(right.x, 0.0f);
    EXPECT_THROW(lookAtCamera({0, 0, 0}, {0, 0, 0}, {0, 1, 0}, 0.7f), std::invalid_argument);
    EXPECT_THROW(lookAtCamera({0, 0, 0}, {0, 1, 0}, {0, 1, 0}, 0.7f), std::invalid_argument);
}

TEST(Camera, OrthographicRaysAreParallelAndSpanTwiceYmagTimesTheImageAspect) {
    Camera c = lookAtCamera({1, 2, 5}, {1, 2, 0}, {0, 1, 0}, 0.7f);
    c.projection = Projection::Orthographic;
    c.ymag = 1.5f;
    const CameraRay centre = cameraRay(c, 320, 240, 640, 480);
    const CameraRay corner = cameraRay(c, 0, 0, 640, 480);  // top left
    const CameraRay bottomRight = cameraRay(c, 640, 480, 640, 480);
    for (const CameraRay& r : {centre, corner, bottomRight}) EXPECT_NEAR(dot(r.direction, Vec3f(0, 0, -1)), 1.0f, 1e-6f);
    EXPECT_NEAR(length(centre.origin - Vec3f(1, 2, 5)), 0.0f, 1e-6f);
    // Half extents: ymag vertically, ymag × 640/480 horizontally; image y runs down.
    EXPECT_NEAR(corner.origin.x, 1 - 1.5f * 640 / 480, 1e-5f);
    EXPECT_NEAR(corner.origin.y, 2 + 1.5f, 1e-5f);
    EXPECT_NEAR(bottomRight.origin.x, 1 + 1.5f * 640 / 480, 1e-5f);
    EXPECT_NEAR(bottomRight.origin.y, 2 - 1.5f, 1e-5f);
}

TEST(Camera, PlacedByANodeLooksDownItsMinusZWithPlusYUp) {
    Camera lens;
    lens.yfov = 0.5f;
    // A node turned 90° about +Y (its −Z now points along −X), at (3, 4, 5); world origin (1, 1, 1).
    const Transform world = Transform::fromTRS({3, 4, 5}, {0, std::sqrt(0.5), 0, std::sqrt(0.5)}, {2, 2, 2});
    const Camera c = placeCamera(lens, world, Vec3d(1, 1, 1));
    EXPECT_NEAR(length(c.position - Vec3f(2, 3, 4)), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(c.forward, Vec3f(-1, 0, 0)), 1.0f, 1e-6f);
    EXPECT_NEAR(dot(c.up, Vec3f(0, 1, 0)), 1.0f, 1e-6f);
    EXPECT_EQ(c.yfov, 0.5f);
}

TEST(RadiosityImage, ConstantRadiosityGivesExactlyBOverPiAndBlackBackground) {
    Scene scene = testscenes::plane(1.0f, 8, Vec3f(0.5f));
    VertexRadiosity solution;
    solution.radiosity.assign(scene.vertexCount(), Vec3f(2.0f, 1.0f, 0.5f));
    EmbreeDevice device;
    SceneBvh bvh(device, scene);
    // Looking straight down at the 2 m plane from 2 m with a 90° field: the plane fills the
    // centre of the image and the corners see the black background.
    const Camera camera = lookAtCamera({0, 2, 0}, {0, 0, 0}, {0, 0, -1}, 1.5707963f);
    const RgbImage image = renderRadiosityImage(scene, bvh, solution, camera, ImageSettings{64, 64, 4, 1});
    const float* centre = &image.pixels[(32 * 64 + 32) * 3];
    EXPECT_NEAR(centre[0], 2.0f / kPi, 1e-6f);
    EXPECT_NEAR(centre[1], 1.0f / kPi, 1e-6f);
    EXPECT_NEAR(centre[2], 0.5f / kPi, 1e-6f);
    EXPECT_EQ(image.pixels[0], 0.0f);
}

TEST(RadiosityImage, InterpolatesLinearlyAcrossTriangles) {
    // Radiosity linear in x over the plane is reproduced exactly by barycentric interpolation.
    Scene scene = testscenes::plane(1.0f, 4, Vec3f(0.5f));
    VertexRadiosity solution;
    for (const Vec3f& p : scene.positions) solution.radiosity.push_back(Vec3f(1.0f + p.x));
    EmbreeDevice device;
    SceneBvh bvh(device, scene);
    const Camera camera = lookAtCamera({0, 1, 0}, {0, 0, 0}, {0, 0, -1}, 1.0f);
    const RgbImage image = renderRadiosityImage(scene, bvh, solution, camera, ImageSettings{33, 33, 1, 1});
    for (int x = 0; x < 33; x += 4) {
        const Vec3f d = cameraRay(camera, x + 0.5f, 16.5f, 33, 33).direction;
        const float hitX = d.x / -d.y;  // where the ray meets y = 0
        EXPECT_NEAR(image.pixels[(16 * 33 + x) * 3], (1.0f + hitX) / kPi, 1e-5f) << "column " << x;
    }
}
