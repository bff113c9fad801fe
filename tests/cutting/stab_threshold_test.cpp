// A stab at a cutting-force threshold (docs/cutting.md, "The point's cut"): a scalpel driven
// along its axis into a block on a fixed base, its point ending below the base's top, as the
// breast's stab ends in the chest wall. The tissue deforms until the point's force reaches the
// threshold, then separates; the run stays finite and slow at every spacing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "engine/solver/cutting.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

struct Stab {
  bool finite = true;
  double max_speed = 0;         // m/s, of any phyxel
  double max_force = 0;         // N, the largest cutting force
  double force_before_cut = 0;  // N, the largest before the first separation
  double min_ratio = 1;         // the shortest live pair against its rest length
  size_t severed = 0;
  int first_cut_substep = -1;
};

// The breast's stab (scenes/breast_resection.json) into a 20 x 36 x 24 mm block (on the breast's
// lattice) of its tissue whose lower third is fixed (z < 0.5 mm): the blade tilted 35 degrees, its
// point from 2 mm above the block to 4.1 mm below the fixed layer's top, at 0.22 m/s. Spacing 4 mm
// / k.
Stab stab_block(double k, double threshold) {
  Material m = test::tissue(6000, 0.45, 40);
  m.density = 980;
  Scene scene = test::box_scene(Vec3(0, -0.016, -0.008), Vec3(0.02, 0.02, 0.016), 0.004 / k, m);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0005)));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.simulation.dt = 0.00023;
  const Vec3 axis(0, 0.573576, 0.819152), end(0.01, 0.004264, -0.004113);
  const double travel = 0.022 / axis.z(), duration = travel / 0.22;
  ToolDesc t;
  t.name = "scalpel";
  t.type = ToolDesc::Type::Scalpel;
  t.shape.type = ToolShape::Type::Capsule;
  t.shape.radius = 0.0006;
  t.shape.length = 0.1;
  t.friction = 0.2;
  t.blade.length = 0.085;
  t.blade.edge = Vec3(-1, 0, 0);
  t.blade.reference_axis = axis;
  t.blade.threshold = threshold;
  t.path = {{0.0, end + travel * axis, axis}, {duration, end, axis}, {duration + 0.02, end, axis}};
  scene.tools.push_back(t);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  const double dt = plan_time_step(scene, set).dt_used;
  const int64_t steps = int64_t(std::ceil((duration + 0.02) / dt));
  test::ToolStepper<double> run(solver, scene.tools, dt);
  Stab out;
  for (int64_t step = 0; step < steps; ++step) {
    run.run(1);
    const ToolContactSample& s = solver.tool_samples().back();
    out.max_force = std::max(out.max_force, std::max(0.0, s.force.dot(axis)));
    const size_t severed = solver.severed_count();
    if (severed == 0) out.force_before_cut = out.max_force;
    if (severed > 0 && out.first_cut_substep < 0) out.first_cut_substep = int(step);
    out.severed = severed;
  }
  const NeighbourLists& nbr = solver.neighbours();
  const std::vector<double>& w = solver.pair_weights();
  for (uint32_t i = 0; i < set.size(); ++i) {
    const Vec3 xi = set.rest[i] + solver.displacement()[i];
    out.finite = out.finite && xi.allFinite() && solver.velocity()[i].allFinite();
    out.max_speed = std::max(out.max_speed, solver.velocity()[i].norm());
    for (uint32_t kk = nbr.offset[i]; kk < nbr.offset[i + 1]; ++kk) {
      if (w[kk] == 0) continue;
      const uint32_t j = nbr.index[kk];
      const Vec3 xj = set.rest[j] + solver.displacement()[j];
      out.min_ratio =
          std::min(out.min_ratio, (xj - xi).norm() / (set.rest[j] - set.rest[i]).norm());
    }
  }
  std::printf(
      "[ stab     ] k %.2g threshold %.3g N: finite %d, speed %.3g m/s, force %.3g N "
      "(%.3g before the first cut, substep %d), %zu pairs cut, shortest pair %.3g\n",
      k, threshold, out.finite, out.max_speed, out.max_force, out.force_before_cut,
      out.first_cut_substep, out.severed, out.min_ratio);
  return out;
}

// At 2 mm the stab passes 0.12 mm from a lattice site: that phyxel rides on the point's cap
// (within its friction cone) and the point's force reaches the threshold as it nears the base.
// Then the tissue ahead of the point parts (its reach): the force stays at the threshold. Without
// it, cuts beside the blade left the point pressing: 0.085 N for a threshold of 0.05 N.
TEST(StabThreshold, ThePointsForceStaysAtTheThresholdOnceItCuts) {
  const double threshold = 0.05;
  const Stab s = stab_block(2.0, threshold);
  EXPECT_TRUE(s.finite);
  EXPECT_LT(s.max_speed, 4.0);  // m/s: below the p-wave speed of 4.8 m/s
  ASSERT_GE(s.first_cut_substep, 0);
  EXPECT_GT(s.force_before_cut, 0.9 * threshold);  // the tissue deforms first
  EXPECT_GT(s.severed, 100u);
  EXPECT_LT(s.max_force, 1.1 * threshold);
}

}  // namespace
}  // namespace phyxel
