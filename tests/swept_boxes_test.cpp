// The swept boxes that the incremental update's envelope is made of (lib/scene/swept_boxes.h).
#include <gtest/gtest.h>

#include "scene/swept_boxes.h"

using namespace qsgi;

namespace {

Bounds3f cubeAt(const Vec3f& corner, float edge) {
    Bounds3f b;
    b.extend(corner);
    b.extend(corner + Vec3f(edge));
    return b;
}

bool inside(const Bounds3f& inner, const Bounds3f& outer) {
    return outer.lower.x <= inner.lower.x && outer.lower.y <= inner.lower.y && outer.lower.z <= inner.lower.z &&
           inner.upper.x <= outer.upper.x && inner.upper.y <= outer.upper.y && inner.upper.z <= outer.upper.z;
}

double volume(const Bounds3f& b) {
    const Vec3f d = b.diagonal();
    return double(d.x) * d.y * d.z;
}

}  // namespace

// A unit cube flying diagonally across a 10 m room in 25 frames: the union of its poses is the
// whole room's diagonal box (1,331 m³ with the cube); eight boxes along its way hold every pose
// and a small part of that.
TEST(SweptBoxes, FollowAMoverAcrossTheRoomAndHoldEveryPose) {
    std::vector<Bounds3f> poses;
    for (int f = 0; f < 25; ++f) poses.push_back(cubeAt(Vec3f(10.0f * float(f) / 24.0f), 1.0f));
    const std::vector<Bounds3f> boxes = sweptBoxes(poses, 8);
    ASSERT_EQ(boxes.size(), 8u);
    for (size_t p = 0; p < poses.size(); ++p) {
        bool held = false;
        for (const Bounds3f& b : boxes) held = held || inside(poses[p], b);
        EXPECT_TRUE(held) << "pose " << p;
    }
    Bounds3f all;
    double total = 0;
    for (const Bounds3f& b : boxes) {
        all.extend(b);
        total += volume(b);
    }
    // Each of the 8 boxes spans about 3 poses along the diagonal: (1 + 10/8)^3 ≈ 11.4 m³ each.
    EXPECT_LT(total, 0.1 * volume(all)) << total << " of " << volume(all);
    EXPECT_EQ(boxes, sweptBoxes(poses, 8));  // the same input, the same boxes
}

// A pause repeats a pose: it is one box, and few poses stay as they are.
TEST(SweptBoxes, APauseIsOnePoseAndFewPosesStayAsTheyAre) {
    const Bounds3f a = cubeAt(Vec3f(0.0f), 1.0f), b = cubeAt(Vec3f(3.0f), 1.0f);
    const std::vector<Bounds3f> boxes = sweptBoxes({a, a, a, b, b, Bounds3f()}, 8);
    ASSERT_EQ(boxes.size(), 2u);
    EXPECT_EQ(boxes[0].lower, a.lower);
    EXPECT_EQ(boxes[1].upper, b.upper);
    // One box asked for: the union.
    const std::vector<Bounds3f> one = sweptBoxes({a, b}, 1);
    ASSERT_EQ(one.size(), 1u);
    EXPECT_EQ(one[0].lower, a.lower);
    EXPECT_EQ(one[0].upper, b.upper);
    EXPECT_TRUE(sweptBoxes({}, 8).empty());
}
