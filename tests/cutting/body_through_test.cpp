// A pair through the blade's body is severed (docs/cutting.md, "Where the cone stays joined at
// K = 2"): a pair along the blade's plane within the body's radius crosses no plane, but the
// body passed through the material it stands for (breast_resection's cone stayed joined so).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "engine/solver/cutting.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

EdgeFrame vertical_blade() {
  EdgeFrame f;  // tip at the origin, axis z, moving along x: the normal is +y
  f.tip = Vec3::Zero();
  f.axis = Vec3::UnitZ();
  f.edge = Vec3::UnitX();
  f.normal = f.axis.cross(f.edge);
  f.length = 0.01;
  f.front = 0.0006;
  return f;
}

TEST(BodyThrough, APairAlongThePlaneBehindTheAxisWithinTheRadiusPassesThroughTheBody) {
  const EdgeFrame f = vertical_blade();
  double t = -1;
  // 0.3 mm off the plane, parallel to it, spanning the axis: through (nearest at the axis).
  EXPECT_TRUE(passes_through_body(Vec3(-0.001, 0.0003, 0.005), Vec3(0.001, 0.0003, 0.005), f, &t));
  EXPECT_NEAR(t, 0.5, 1e-9);
  // Only behind the axis: a pair from 0.2 mm behind it still passes, nearest at its start.
  EXPECT_TRUE(
      passes_through_body(Vec3(-0.0002, -0.0003, 0.005), Vec3(-0.002, -0.0003, 0.005), f, &t));
  EXPECT_NEAR(t, 0.0, 1e-9);
  // Ahead of the axis (where the front still pushes), beyond the radius, past the ends: not.
  EXPECT_FALSE(passes_through_body(Vec3(0.0001, 0.0003, 0.005), Vec3(0.002, 0.0003, 0.005), f, &t));
  EXPECT_FALSE(passes_through_body(Vec3(-0.001, 0.0007, 0.005), Vec3(0.001, 0.0007, 0.005), f, &t));
  EXPECT_FALSE(passes_through_body(Vec3(-0.001, 0.0003, -1e-4), Vec3(0.001, 0.0003, -1e-4), f, &t));
  EXPECT_FALSE(
      passes_through_body(Vec3(-0.001, 0.0003, 0.0101), Vec3(0.001, 0.0003, 0.0102), f, &t));
  // A pair through the axis obliquely, from beside the blade to below its tip: through.
  EXPECT_TRUE(
      passes_through_body(Vec3(-0.0004, 0.002, 0.001), Vec3(-0.0004, -0.002, -0.001), f, &t));
}

// test::circle_cut at 0.005 N, stopped at its end pose: no live pair between phyxels the blade
// keeps on opposite sides passes through its body behind its axis (before the rule, such pairs
// stayed: they cross no plane).
TEST(BodyThrough, ACircleCutLeavesNoPairThroughItsBodyBetweenPhyxelsKeptApart) {
  const Scene scene = test::circle_cut(0.005);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  test::ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  run.run(int64_t(0.4 / scene.simulation.dt) + 10);
  ASSERT_EQ(solver.first_non_finite(), -1);
  ASSERT_GT(solver.severed_count(), 300u);
  const ToolDesc& blade = scene.tools[0];
  EdgeFrame f = vertical_blade();
  f.tip = blade.path.back().position;
  f.edge = Vec3(-f.tip.y(), f.tip.x(), 0).normalized();  // the circle's tangent, the motion
  f.normal = f.axis.cross(f.edge);
  std::vector<uint32_t> side(set.size(), kSideNone);
  for (const BladeSide& b : solver.blade_sides(0)) side[b.phyxel] = b.side;
  const NeighbourLists& nbr = solver.neighbours();
  size_t through = 0, apart = 0;
  for (uint32_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      if (j < i || solver.pair_weights()[k] == 0.0 || !kept_apart(side[i], side[j])) continue;
      ++apart;
      double t = 0;
      through += passes_through_body(set.rest[i] + solver.displacement()[i],
                                     set.rest[j] + solver.displacement()[j], f, &t);
    }
  std::printf("[ cutting  ] %zu live pairs kept apart, %zu through the body\n", apart, through);
  EXPECT_EQ(through, 0u);
}

}  // namespace
}  // namespace phyxel
