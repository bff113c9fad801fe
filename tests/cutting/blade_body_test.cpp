// The blade's body separates what it passes through (docs/cutting.md, "The blade's body"): a
// blade turned about its tip inside the tissue reaches almost nothing ahead near that pivot, so
// without the body's strip its capsule ploughed the phyxels there along instead of cutting them
// (what kept breast_resection's cut open at twice its resolution).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "engine/solver/cutting.h"
#include "tests/cutting/cutting_fixtures.h"

namespace phyxel {
namespace {

using test::ToolStepper;

// A blade 3 cm long, its tip 3 mm deep in the beam at x = 2 cm, turned about the tip by 40
// degrees around x during [0, 20 ms]; a body of radius 0.8 mm, a reach of 1 um.
ToolDesc turning_scalpel(const Vec3& tip, double* final_angle) {
  ToolDesc t = test::crossing_scalpel(tip.x(), tip.z(), 0.03, 0.0, 0.02);
  t.shape.radius = 0.0008;
  t.blade.reach = 1e-6;
  t.path.clear();
  const int keys = 9;
  for (int k = 0; k < keys; ++k) {
    const double a = 40.0 * std::numbers::pi / 180.0 * k / (keys - 1);
    t.path.push_back({0.02 * k / (keys - 1), tip, Vec3(0, std::sin(a), std::cos(a))});
  }
  *final_angle = 40.0 * std::numbers::pi / 180.0;
  return t;
}

TEST(BladeBody, NoPairPassesThroughTheBodyOfABladeTurnedAboutItsTip) {
  Scene scene = test::clamped_beam(5e4, 5);
  scene.simulation.gravity = Vec3::Zero();
  const Vec3 tip(0.02, 0.002, 0.003);
  double angle = 0;
  scene.tools.push_back(turning_scalpel(tip, &angle));
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  ToolStepper<double> run(solver, scene.tools, scene.simulation.dt);
  run.run(200);  // the blade stops turning at t = 20 ms
  ASSERT_EQ(solver.first_non_finite(), -1);
  ASSERT_GT(solver.severed_count(), 0u);
  // The body's strip at the final pose: within its radius of the blade, in the blade's plane.
  const Vec3 axis(0, std::sin(angle), std::cos(angle)), edge(0, std::cos(angle), -std::sin(angle));
  const double r = scene.tools[0].shape.radius, length = scene.tools[0].blade.length;
  const Vec3 end = tip + length * axis;
  const std::array<Vec3, 4> strip = {tip - r * edge, end - r * edge, end + r * edge,
                                     tip + r * edge};
  const NeighbourLists& nbr = solver.neighbours();
  size_t through = 0;
  for (uint32_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      if (j < i || solver.pair_weights()[k] == 0.0) continue;
      const Vec3 xi = set.rest[i] + solver.displacement()[i];
      const Vec3 xj = set.rest[j] + solver.displacement()[j];
      through += segment_crosses_quad<double>(xi, xj, strip);
    }
  EXPECT_EQ(through, 0u) << "live pairs through the blade's body";
}

}  // namespace
}  // namespace phyxel
