// The grasper on the GPU against the CPU reference (engine/solver/grasper.h): the same phyxels
// taken when the jaws close, the same motion while they hold and pull (turning the tool's axis
// too), the same force on the tool, the same grip when held phyxels are removed, and the same
// letting go, with the motions given chunk by chunk as the run loop does.
#include <gtest/gtest.h>

#include <cstdio>

#include "tests/gpu_solver/gpu_solver_fixture.h"
#include "tests/surgery/grasper_fixtures.h"

namespace phyxel::gpu::test {
namespace {

struct GripRun {
  std::vector<std::vector<Vec3>> u;         // after each chunk
  std::vector<std::vector<uint32_t>> held;  // after each chunk
  std::vector<ToolContactSample> samples;   // every substep
};

GripRun grip(Solver& solver, const Scene& scene, const PhyxelSet& set) {
  GripRun out;
  advance_tools_in_chunks(solver, scene, set, scene.simulation.steps, 8, [&](const auto& felt) {
    out.samples.insert(out.samples.end(), felt.begin(), felt.end());
    out.u.push_back(solver.read_state(false).displacement);
    out.held.push_back(solver.tools()->held_phyxels(0));
    // At 24 ms two held phyxels are aspirated: they leave the grip.
    if (out.held.size() == 3 && out.held.back().size() > 2)
      solver.removal()->remove_phyxels({out.held.back()[0], out.held.back()[1]});
  });
  return out;
}

TEST_F(GpuSolverTest, GrasperCapturesHoldsAndReleasesAsTheCpu) {
  // The jaws close at 2 ms on the end of the bar, pull it 2 mm while the tool turns 17 degrees,
  // and open at 60 ms; 80 ms in all.
  const Scene scene = parse_scene(phyxel::test::bar_json(phyxel::test::kBarLength + 0.0006, 0.0027,
                                                         0.002, 0.06, 0.08, "[0.3, 0, 1]"),
                                  "bar.json");
  const PhyxelSet set = sample_scene(scene);
  auto cpu = make_cpu_solver(set, Vec3::Zero(), 1);
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  const GripRun c = grip(*cpu, scene, set);
  const GripRun g = grip(gpu, scene, set);
  ASSERT_EQ(c.held.size(), g.held.size());
  size_t most = 0;
  double worst_u = 0, largest_u = 0;
  for (size_t k = 0; k < c.held.size(); ++k) {
    SCOPED_TRACE("chunk " + std::to_string(k));
    EXPECT_EQ(c.held[k], g.held[k]);
    most = std::max(most, c.held[k].size());
    worst_u = std::max(worst_u, max_difference(c.u[k], g.u[k]));
    largest_u = std::max(largest_u, max_norm(c.u[k]));
  }
  EXPECT_GT(most, 10u);
  ASSERT_GT(c.held.size(), 4u);
  EXPECT_EQ(c.held[3].size() + 2, c.held[2].size()) << "the removed phyxels are still held";
  EXPECT_TRUE(c.held.back().empty()) << "the jaws did not open";
  EXPECT_GT(largest_u, 0.0015);
  EXPECT_LT(worst_u, 1e-6);  // m
  ASSERT_EQ(c.samples.size(), g.samples.size());
  double worst_f = 0, largest_f = 0;
  for (size_t k = 0; k < c.samples.size(); ++k) {
    EXPECT_EQ(c.samples[k].held, g.samples[k].held) << k;
    largest_f = std::max(largest_f, c.samples[k].force.norm());
    worst_f = std::max(worst_f, (c.samples[k].force - g.samples[k].force).norm());
  }
  EXPECT_GT(largest_f, 1e-4);  // N
  EXPECT_LT(worst_f, 0.01 * largest_f);
  std::printf(
      "[ grasper  ] held up to %zu; |u| up to %.3g m, GPU within %.3g m; force up to %.3g N, "
      "within %.3g N\n",
      most, largest_u, worst_u, largest_f, worst_f);
}

}  // namespace
}  // namespace phyxel::gpu::test
