// Steps of many substeps, advanced in polled chunks (engine/run/long_step.h): the same states
// bit for bit as one advance, and a stop in the middle of a step goes back to its start.
#include <gtest/gtest.h>

#include "engine/run/long_step.h"
#include "engine/run/simulation.h"
#include "engine/solver/contact.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

struct Fixture {
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.01, 0.01, 0.01), 0.0025, test::tissue(1e5, 0.3, 50));
  PhyxelSet set;
  double dt = 0;
  Fixture() {
    scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001)));
    set = sample_scene(scene);
    dt = 0.9 * plan_time_step(scene, set).dt_stable;
  }
};

void expect_same_state(Solver& a, Solver& b, size_t n) {
  const PointState x = a.read_state(false), y = b.read_state(false);
  for (size_t i = 0; i < n; ++i) {
    ASSERT_EQ(x.displacement[i], y.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(x.velocity[i], y.velocity[i]) << "phyxel " << i;
  }
}

TEST(LongSteps, PolledChunksGiveTheStatesOfOneAdvance) {
  Fixture f;
  auto whole = make_cpu_solver(f.set, Vec3(0, 0, -9.81), 1, false);
  auto chunked = make_cpu_solver(f.set, Vec3(0, 0, -9.81), 1, false);
  whole->advance(3 * 300, f.dt);
  int polls = 0;
  // A poll time of zero makes every chunk one substep.
  const int64_t done = advance_long_steps(
      *chunked, 3, 300, f.dt, [&] { return ++polls < 0; }, 0);
  EXPECT_EQ(done, 3);
  EXPECT_GE(polls, 3 * 299);
  expect_same_state(*whole, *chunked, f.set.size());
}

TEST(LongSteps, AStopMidStepGoesBackToTheStepsStart) {
  Fixture f;
  auto reference = make_cpu_solver(f.set, Vec3(0, 0, -9.81), 1, false);
  auto stopped = make_cpu_solver(f.set, Vec3(0, 0, -9.81), 1, false);
  reference->advance(2 * 300, f.dt);
  int polls = 0;
  // Stops at the 700th poll: in the third step.
  const int64_t done = advance_long_steps(
      *stopped, 5, 300, f.dt, [&] { return ++polls >= 700; }, 0);
  EXPECT_EQ(done, 2);
  // Going on from there gives what a run that never stopped has.
  reference->advance(300, f.dt);
  stopped->advance(300, f.dt);
  expect_same_state(*reference, *stopped, f.set.size());
}

// A probe pressing into the block: the polled chunks of advance_long_tool_steps give the states
// and the per-step records of one advance of the same steps; a stop inside a step ends there.
struct ProbeFixture : Fixture {
  ProbeFixture() {
    ToolDesc probe;
    probe.name = "probe";
    probe.shape.radius = 0.003;
    probe.path = {{0, Vec3(0.005, 0.005, 0.0135), Vec3::UnitZ()},
                  {10 * 300 * dt, Vec3(0.005, 0.005, 0.009), Vec3::UnitZ()}};
    scene.tools = {probe};
  }
  std::unique_ptr<Solver> solver() const {
    auto s = make_cpu_solver(set, Vec3(0, 0, -9.81), 1, false);
    s->tools()->set_tools(contact_tools(scene.tools));
    return s;
  }
};

TEST(LongSteps, PolledToolChunksGiveTheStatesAndRecordsOfOneAdvance) {
  ProbeFixture f;
  auto whole = f.solver(), chunked = f.solver();
  ToolTrack whole_track(f.scene.tools, {}), chunked_track(f.scene.tools, {});
  const std::vector<ToolStepRecord> expected =
      advance_with_tools(*whole, whole_track, 0, 3, 300, f.dt);
  const PolledToolSteps got = advance_long_tool_steps(
      *chunked, chunked_track, 0, 3, 300, f.dt, [] { return false; }, 0);
  EXPECT_EQ(got.steps, 3);
  EXPECT_EQ(got.within_step, 0);
  ASSERT_EQ(got.records.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(got.records[k].force, expected[k].force) << k;
    EXPECT_EQ(got.records[k].contacts, expected[k].contacts) << k;
  }
  EXPECT_GT(expected.back().contacts, 0u) << "the probe must touch the block";
  expect_same_state(*whole, *chunked, f.set.size());
}

TEST(LongSteps, AStopInsideAToolStepEndsThere) {
  ProbeFixture f;
  auto solver = f.solver();
  ToolTrack track(f.scene.tools, {});
  int polls = 0;
  const PolledToolSteps got = advance_long_tool_steps(
      *solver, track, 0, 5, 300, f.dt, [&] { return ++polls >= 400; }, 0);
  EXPECT_EQ(got.steps, 1);
  EXPECT_EQ(got.within_step, 100);  // poll 300 ends step 1; poll 400 is 100 substeps on
  EXPECT_EQ(got.records.size(), 1u);
}

}  // namespace
}  // namespace phyxel
