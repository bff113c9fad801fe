// Steps of many substeps, advanced in polled chunks (engine/run/long_step.h): the same states
// bit for bit as one advance, and a stop in the middle of a step goes back to its start.
#include <gtest/gtest.h>

#include "engine/run/long_step.h"
#include "engine/run/simulation.h"
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

}  // namespace
}  // namespace phyxel
