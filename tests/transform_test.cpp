// Transform::isInvertible judges a matrix against its own scale (issue 23): a model built in
// micrometres is as invertible as one in metres; a flattened or non-finite one is not.
#include <gtest/gtest.h>

#include <cmath>

#include "util/vecmath.h"

using namespace qsgi;

TEST(Transform, InvertibilityIsRelativeToTheMatrixsOwnScale) {
    const std::array<double, 4> turn{0.2, 0.3, 0.1, std::sqrt(1 - 0.04 - 0.09 - 0.01)};
    for (double s : {1.0, 1e-5, 1e-12, 1e5, 1e12}) {
        SCOPED_TRACE(s);
        EXPECT_TRUE(Transform::fromTRS(Vec3d(1, 2, 3), turn, Vec3d(s)).isInvertible());
        EXPECT_TRUE(Transform::fromTRS(Vec3d(0.0), turn, Vec3d(s, 2 * s, 0.5 * s)).isInvertible());
        EXPECT_FALSE(Transform::fromTRS(Vec3d(0.0), turn, Vec3d(s, 0, s)).isInvertible()) << "flattened";
    }
    // Two columns almost parallel: degenerate whatever the scale.
    Transform sheared = Transform::fromTRS(Vec3d(0.0), {0, 0, 0, 1}, Vec3d(1e-5));
    sheared.at(0, 1) = 1e-5;
    sheared.at(1, 1) = 1e-5 * 1e-12;
    EXPECT_FALSE(sheared.isInvertible());
    Transform infinite = Transform::fromTRS(Vec3d(0.0), {0, 0, 0, 1}, Vec3d(1.0));
    infinite.at(0, 3) = INFINITY;
    EXPECT_FALSE(infinite.isInvertible());
}
