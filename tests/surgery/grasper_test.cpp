// The grasper on the CPU reference (engine/solver/grasper.h, engine/solver/cpu_solver_grasp.cpp):
// what the jaws take when they close, the force of a bar held and pulled against E A strain,
// letting go, and fixed tissue never taken.
#include "engine/solver/grasper.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "engine/run/simulation.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/scene/scene.h"
#include "tests/surgery/grasper_fixtures.h"

namespace phyxel {
namespace {

using test::bar_json;
using test::kBarLength;

constexpr double kYoung = 1e4;      // Pa, bar_json's
constexpr double kSpacing = 0.001;  // m, bar_json's

struct BarRun {
  Scene scene;
  PhyxelSet set;
  std::unique_ptr<Solver> solver;
  std::vector<ToolStepRecord> records;  // per step (one tool)
};

// Runs the scene's steps on the CPU in chunks of 16 steps, as the run loop does.
BarRun run_bar(const std::string& json, int64_t steps = -1) {
  BarRun r{parse_scene(json, "bar.json"), {}, nullptr, {}};
  r.set = sample_scene(r.scene);
  r.solver = make_cpu_solver(r.set, Vec3::Zero(), 1);
  r.solver->tools()->set_tools(contact_tools(r.scene.tools));
  const TimeStepPlan plan = plan_time_step(r.scene, r.set);
  ToolTrack track(r.scene.tools, {});
  const int64_t total = steps >= 0 ? steps : r.scene.simulation.steps;
  for (int64_t s = 0; s < total; s += 16) {
    const int64_t n = std::min<int64_t>(16, total - s);
    const auto rec = advance_with_tools(*r.solver, track, s, n, plan.substeps, plan.dt_used);
    r.records.insert(r.records.end(), rec.begin(), rec.end());
  }
  return r;
}

// The non-fixed phyxels within `reach` of `tip` at rest, ascending.
std::vector<uint32_t> within(const PhyxelSet& set, const Vec3& tip, double reach) {
  std::vector<uint32_t> out;
  for (uint32_t i = 0; i < set.size(); ++i)
    if (!(set.flags[i] & kFixed) && (set.rest[i] - tip).norm() <= reach) out.push_back(i);
  return out;
}

TEST(Grasper, TheGripTurnsWithTheToolsAxis) {
  // Captured 1 mm down the axis (z) from the tip; the tool then moves by (1, 2, 3) cm and turns
  // its axis to x: the point is 1 mm down x from the new tip, and moves with the tool.
  const ToolPose at_capture{Vec3(0.01, 0, 0), Vec3::UnitZ()};
  const Vec3 offset = grip_offset(at_capture, Vec3(0.01, 0, -0.001));
  EXPECT_LT((grip_point(at_capture, offset) - Vec3(0.01, 0, -0.001)).norm(), 1e-15);
  const ToolPose turned{Vec3(0.02, 0.02, 0.03), Vec3::UnitX()};
  EXPECT_LT((grip_point(turned, offset) - Vec3(0.019, 0.02, 0.03)).norm(), 1e-15);
  const GripTarget target = grip_target({at_capture, turned}, offset, 0.5);
  EXPECT_LT((target.velocity - (Vec3(0.019, 0.02, 0.03) - Vec3(0.01, 0, -0.001)) / 0.5).norm(),
            1e-14);
}

TEST(Grasper, ClosesOnThePhyxelsWithinReachOfTheTip) {
  // Tip 0.6 mm beyond the free end, reach 2.7 mm: a cap of the end (no phyxel at that distance).
  const Vec3 tip(kBarLength + 0.0006, 0, 0);
  BarRun r = run_bar(bar_json(tip.x(), 0.0027, 0, 0, 0), 4);
  const std::vector<uint32_t> expected = within(r.set, tip, 0.0027);
  ASSERT_GT(expected.size(), 10u);
  EXPECT_EQ(r.solver->tools()->held_phyxels(0), expected);
  EXPECT_EQ(r.records.back().held, expected.size());
  EXPECT_EQ(r.records.front().held, 0u);  // the jaws close at 2 ms
}

TEST(Grasper, ABarHeldAndPulledPullsBackWithEAStrain) {
  // The tip far beyond the end with a reach to just past x = 28.5 mm: the two end layers
  // (x = 29 and 30 mm) whole. The free length runs from the last fixed layer (x = 1 mm) to the
  // first held one (x = 29 mm); pulled by 0.28 mm (1 % strain), then held while it settles.
  const double tip_x = 0.08, reach = tip_x - 0.0285, pull = 0.00028;
  BarRun r = run_bar(bar_json(tip_x, reach, pull, 0, 0.4));
  const size_t layer = within(r.set, Vec3(tip_x, 0, 0), reach).size();
  EXPECT_EQ(layer, 50u);  // two layers of 5 x 5
  // The section the phyxels of one layer stand for: their volume per spacing.
  double area = 0;
  for (uint32_t i = 0; i < r.set.size(); ++i)
    if (std::abs(r.set.rest[i].x() - 0.015) < 1e-9) area += r.set.volume[i] / kSpacing;
  const double expected = kYoung * area * pull / 0.028;
  const Vec3 f = r.records.back().force;
  std::printf("[ grasper  ] pulled 1 %% strain: force %.4g N (x), E A strain %.4g N (%+.1f %%)\n",
              f.x(), expected, 100 * (-f.x() / expected - 1));
  EXPECT_LT(f.x(), 0);  // the tissue pulls the jaws back toward the fixed end
  EXPECT_NEAR(-f.x(), expected, 0.1 * expected);
  EXPECT_LT(std::hypot(f.y(), f.z()), 0.01 * expected);
}

TEST(Grasper, LetsGoWhenItOpens) {
  // Pulled 2 mm, opened at 60 ms: nothing held, no force, and the end springs back.
  const Vec3 tip(kBarLength + 0.0006, 0, 0);
  BarRun r = run_bar(bar_json(tip.x(), 0.0027, 0.002, 0.06, 0.3));
  EXPECT_TRUE(r.solver->tools()->held_phyxels(0).empty());
  EXPECT_EQ(r.records.back().held, 0u);
  EXPECT_GT(r.records[50].held, 0u);  // held at 51 ms
  EXPECT_GT(r.records[50].force.norm(), 1e-4);
  EXPECT_EQ(r.records.back().force.norm(), 0.0);
  const PointState s = r.solver->read_state(false);
  double end_u = 0;
  for (const uint32_t i : within(r.set, tip, 0.0027))
    end_u = std::max(end_u, s.displacement[i].x());
  EXPECT_LT(end_u, 0.25 * 0.002) << "the end did not spring back";
}

TEST(Grasper, RemovedPhyxelsLeaveTheGrip) {
  const Vec3 tip(kBarLength + 0.0006, 0, 0);
  BarRun r = run_bar(bar_json(tip.x(), 0.0027, 0, 0, 0), 4);
  std::vector<uint32_t> held = r.solver->tools()->held_phyxels(0);
  ASSERT_GT(held.size(), 3u);
  r.solver->removal()->remove_phyxels({held[0], held[2]});  // aspirated
  held.erase(held.begin() + 2);
  held.erase(held.begin());
  EXPECT_EQ(r.solver->tools()->held_phyxels(0), held);
  ToolTrack track(r.scene.tools, {});
  const TimeStepPlan plan = plan_time_step(r.scene, r.set);
  const auto rec = advance_with_tools(*r.solver, track, 4, 1, plan.substeps, plan.dt_used);
  EXPECT_EQ(rec.back().held, held.size());
}

TEST(Grasper, NeverTakesFixedPhyxels) {
  // A reach over the whole bar: every moving phyxel is taken, no fixed one.
  BarRun r = run_bar(bar_json(0.015, 0.05, 0, 0, 0), 4);
  const std::vector<uint32_t> held = r.solver->tools()->held_phyxels(0);
  size_t moving = 0;
  for (uint32_t i = 0; i < r.set.size(); ++i) moving += (r.set.flags[i] & kFixed) ? 0 : 1;
  EXPECT_EQ(held.size(), moving);
  for (const uint32_t i : held) EXPECT_FALSE(r.set.flags[i] & kFixed) << i;
}

}  // namespace
}  // namespace phyxel
