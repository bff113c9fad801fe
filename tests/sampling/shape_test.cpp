// Inside tests and bounds of the analytic shapes, with their boundary tolerance.
#include <gtest/gtest.h>

#include "engine/geometry/shape.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

TEST(ShapeContains, BoxIncludesItsBoundaryWithinTheTolerance) {
  const Shape b = box(Vec3(0, 0, 0), Vec3(0.1, 0.02, 0.03));
  EXPECT_TRUE(shape_contains(b, Vec3(0.05, 0.01, 0.01)));
  EXPECT_TRUE(shape_contains(b, Vec3(0, 0, 0)));
  EXPECT_TRUE(shape_contains(b, Vec3(0.1, 0.02, 0.03)));
  EXPECT_FALSE(shape_contains(b, Vec3(0.1 + 1e-12, 0.01, 0.01)));
  EXPECT_TRUE(shape_contains(b, Vec3(0.1 + 1e-12, 0.01, 0.01), 2e-12));
  EXPECT_FALSE(shape_contains(b, Vec3(0.05, -1e-6, 0.01), 1e-9));
  const Eigen::AlignedBox3d bounds = shape_bounds(b);
  EXPECT_EQ(bounds.min(), Vec3(0, 0, 0));
  EXPECT_EQ(bounds.max(), Vec3(0.1, 0.02, 0.03));
}

TEST(ShapeContains, SphereAndEllipsoid) {
  const Shape s = sphere(Vec3(1, 2, 3), 0.5);
  EXPECT_TRUE(shape_contains(s, Vec3(1.5, 2, 3)));
  EXPECT_FALSE(shape_contains(s, Vec3(1.5 + 1e-9, 2, 3)));
  EXPECT_TRUE(shape_contains(s, Vec3(1.5 + 1e-9, 2, 3), 2e-9));
  EXPECT_FALSE(shape_contains(s, Vec3(1.36, 2.36, 3)));  // |d| = 0.509
  EXPECT_EQ(shape_bounds(s).min(), Vec3(0.5, 1.5, 2.5));
  EXPECT_EQ(shape_bounds(s).max(), Vec3(1.5, 2.5, 3.5));

  const Shape e = ellipsoid(Vec3(0, 0, 0), Vec3(0.4, 0.2, 0.1));
  EXPECT_TRUE(shape_contains(e, Vec3(0.4, 0, 0)));
  EXPECT_TRUE(shape_contains(e, Vec3(0, 0, -0.1)));
  EXPECT_FALSE(shape_contains(e, Vec3(0, 0, 0.1 + 1e-9)));
  // The tolerance is a distance: 1e-9 m off the surface along the short or the long axis.
  EXPECT_TRUE(shape_contains(e, Vec3(0, 0, 0.1 + 1e-9), 1.01e-9));
  EXPECT_FALSE(shape_contains(e, Vec3(0.4 + 2e-9, 0, 0), 1e-9));
  EXPECT_TRUE(shape_contains(e, Vec3(0.4 + 2e-9, 0, 0), 2.01e-9));
  EXPECT_FALSE(shape_contains(e, Vec3(0.3, 0.15, 0)));  // 0.5625 + 0.5625 > 1
  EXPECT_EQ(shape_bounds(e).min(), Vec3(-0.4, -0.2, -0.1));
}

}  // namespace
}  // namespace phyxel::test
