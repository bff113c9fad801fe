// Skipping on the GPU through run_simulation, as tests/skip/pass_selection_test.cpp does on the
// CPU: --no-skip gives the same bits for the moving phyxels, and a block that falls asleep and
// is woken by a load ends where the CPU's does.
#include <cmath>

#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// tests/skip/pass_selection_test.cpp's scenes: a soft block whose lower half is clamped,
// sagging under gravity; the sleepy one also sleeps and gets a push on its top face at 0.15 s.
Scene clamped_block() {
  Scene scene = box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.03), 0.0025, tissue(2e4, 0.3, 150));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.objects[0].fixed.push_back(box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.0151)));
  return scene;
}

Scene sleepy_block() {
  Scene scene = clamped_block();
  scene.simulation.sleep = {true, 1e-12, 200};
  Load push;
  push.region = box_shape(Vec3(-1, -1, 0.0299), Vec3(1, 1, 1));
  push.force = Vec3(0.002, 0, 0);
  push.from = 0.15;
  scene.objects[0].loads.push_back(push);
  return scene;
}

struct RunOutcome {
  RunResult result;
  PointState state;
  size_t stress_pass = 0, force_pass = 0;  // at the end
};

RunOutcome run(Solver& solver, Scene scene, const PhyxelSet& set, int64_t steps, bool select) {
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  RunOptions options;
  options.steps = steps;
  options.pass_selection = select;
  RunOutcome r;
  r.result = run_simulation(scene, set, solver, options);
  r.state = solver.read_state(false);
  r.stress_pass = solver.pass_selection()->stress_pass_size();
  r.force_pass = solver.pass_selection()->force_pass_size();
  return r;
}

TEST_F(GpuSolverTest, NoSkipThroughTheRunLoopGivesTheSameBits) {
  const Scene scene = clamped_block();
  const PhyxelSet set = sample_scene(scene);
  GpuSolver skip_solver(ctx(), set, scene.simulation.gravity);
  GpuSolver all_solver(ctx(), set, scene.simulation.gravity);
  const RunOutcome skip = run(skip_solver, scene, set, 600, true);
  const RunOutcome all = run(all_solver, scene, set, 600, false);
  size_t fixed = 0;
  for (uint32_t f : set.flags) fixed += (f & kFixed) ? 1 : 0;
  EXPECT_EQ(skip.force_pass, set.size() - fixed);
  EXPECT_LT(skip.stress_pass, set.size());
  EXPECT_EQ(all.force_pass, set.size());
  EXPECT_EQ(all.stress_pass, set.size());
  ASSERT_GT(max_norm(all.state.displacement), 0);
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(skip.state.displacement[i], all.state.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(skip.state.velocity[i], all.state.velocity[i]) << "phyxel " << i;
  }
}

TEST_F(GpuSolverTest, SleepyBlockSleepsWakesAndEndsWhereTheCpuDoes) {
  const Scene scene = sleepy_block();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const int64_t load_step = static_cast<int64_t>(std::ceil(0.15 / dt));

  // Up to just before the load: asleep, every pass empty, at rest on the GPU.
  {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    const RunOutcome early = run(gpu, scene, set, load_step - 1, true);
    EXPECT_GE(early.result.sleeps, 1);
    EXPECT_EQ(early.result.wakes, 0);
    EXPECT_EQ(early.force_pass, 0u);
    EXPECT_EQ(early.stress_pass, 0u);
    EXPECT_EQ(max_norm(early.state.velocity), 0.0);
    EXPECT_GT(max_norm(early.state.displacement), 0);  // it sagged before it slept
  }

  // Past the load: it wakes, moves sideways and settles where the CPU's does.
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  const RunOutcome g = run(gpu, scene, set, load_step + 3000, true);
  const auto cpu = make_cpu_solver(set, scene.simulation.gravity, 1);
  const RunOutcome c = run(*cpu, scene, set, load_step + 3000, true);
  EXPECT_GE(g.result.sleeps, 1);
  EXPECT_EQ(g.result.wakes, c.result.wakes);
  EXPECT_GE(g.result.wakes, 1);
  EXPECT_EQ(g.result.load_changes, 1);
  EXPECT_FALSE(g.result.non_finite);
  double sideways = 0;
  for (const Vec3& u : g.state.displacement) sideways = std::max(sideways, u.x());
  EXPECT_GT(sideways, 1e-5);
  const double scale = max_norm(c.state.displacement);
  EXPECT_LE(max_difference(g.state.displacement, c.state.displacement), 1e-4 * scale);
}

}  // namespace
}  // namespace phyxel::gpu::test
