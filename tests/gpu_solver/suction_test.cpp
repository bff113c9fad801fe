// The aspirator on the GPU against the CPU reference (engine/surgery/suction.h): the same pull on
// the tissue and the same force on the tube, substep by substep, with the motions given chunk by
// chunk as the run loop does; a run that aspirates on the GPU removes tissue near the mouth,
// accounts it, stays finite and takes about as much as the CPU's.
#include <gtest/gtest.h>

#include "engine/run/simulation.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

struct PullRun {
  std::vector<Vec3> u;
  std::vector<ToolContactSample> samples;
};

PullRun pull(Solver& solver, const Scene& scene, const PhyxelSet& set, int64_t steps) {
  PullRun out;
  advance_tools_in_chunks(solver, scene, set, steps, 16, [&](const auto& felt) {
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
  });
  out.u = solver.read_state(false).displacement;
  return out;
}

TEST_F(GpuSolverTest, SuctionPullsTheTissueAndTheTubeAsTheCpu) {
  const Scene scene = parse_scene(phyxel::test::suction_block_json(1e6), "block.json");
  const PhyxelSet set = sample_scene(scene);
  auto cpu = make_cpu_solver(set, Vec3::Zero(), 1);
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  // 16 steps: the tissue rises into the mouth and presses on it. Held there longer, a phyxel at
  // the mouth goes in and out of contact each substep, and float against double decides which
  // (1e-9 m agreement at 16 steps, 0.5 mm at 64 on lavapipe; without contact 2e-10 m at 64).
  const PullRun c = pull(*cpu, scene, set, 16);
  const PullRun g = pull(gpu, scene, set, 16);
  const double scale = max_norm(c.u);
  EXPECT_GT(scale, 1e-4) << "the suction moved nothing";
  EXPECT_LT(max_difference(c.u, g.u), 1e-4 * scale);
  ASSERT_EQ(c.samples.size(), g.samples.size());
  double worst = 0, largest = 0;
  for (size_t k = 0; k < c.samples.size(); ++k) {
    largest = std::max(largest, c.samples[k].force.norm());
    worst = std::max(worst, (c.samples[k].force - g.samples[k].force).norm());
  }
  EXPECT_GT(largest, 0.01);  // N: the tube holds the tissue it pulls
  EXPECT_LT(worst, 1e-4 * largest);
  std::printf(
      "[ suction  ] |u| up to %.3g m, GPU within %.3g m; force up to %.3g N, within %.3g N\n",
      scale, max_difference(c.u, g.u), largest, worst);
}

TEST_F(GpuSolverTest, AspirationOnTheGpuRemovesAndAccountsTissueAsTheCpu) {
  const Scene scene = parse_scene(phyxel::test::suction_block_json(1000, true), "block.json");
  const PhyxelSet set = sample_scene(scene);
  RunOptions options;
  options.steps = 300;
  auto cpu = make_cpu_solver(set, Vec3::Zero(), 1);
  const RunResult c = run_simulation(scene, set, *cpu, options);
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  const RunResult g = run_simulation(scene, set, gpu, options);
  ASSERT_TRUE(g.aspirating);
  EXPECT_GE(g.aspiration.events, 2);
  EXPECT_EQ(gpu.first_non_finite(), -1);
  const double cm = c.aspiration.removed_mass[0], gm = g.aspiration.removed_mass[0];
  EXPECT_GT(gm, 0);
  // Tearing cascades amplify float-against-double differences over a run: the same amount of
  // tissue within a quarter, not the same phyxels.
  EXPECT_NEAR(gm, cm, 0.25 * cm);
  std::printf(
      "[ suction  ] aspirated %.3f g on the CPU in %lld events, %.3f g on the GPU in %lld\n",
      1e3 * cm, static_cast<long long>(c.aspiration.events), 1e3 * gm,
      static_cast<long long>(g.aspiration.events));
}

}  // namespace
}  // namespace phyxel::gpu::test
