// The tool contact inside the force pass (GpuSolverOptions::contact_in_force: while tearing,
// solver_force_tear does tool_contact's work after the drift and tool_contact_reduce sums the
// samples after the advance) against tool_contact after it: the same bits in every state, tool
// force and aspirated amount, over a run that tears and aspirates (removed candidates).
#include <gtest/gtest.h>

#include <algorithm>

#include "engine/run/simulation.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

struct AspirationRun {
  RunResult result;
  PointState state;
  std::vector<Vec3> forces;  // per step, the aspirator's
  bool rows_timed = false;   // a profile of the solver after the run has the rows' reduction
};

AspirationRun aspirate(Context& ctx, const Scene& scene, const PhyxelSet& set, bool in_force,
                       uint32_t lanes) {
  GpuSolverOptions options;
  options.contact_in_force = in_force;
  options.lanes = lanes;  // the contact follows the lanes' sum in lane 0
  GpuSolver gpu(ctx, set, Vec3::Zero(), options);
  RunOptions run;
  run.steps = 200;
  AspirationRun out;
  run.on_tool_step = [&](int64_t, double, const std::vector<ToolStepRecord>& records) {
    out.forces.push_back(records.at(0).force);
  };
  out.result = run_simulation(scene, set, gpu, run);
  out.state = gpu.read_state(false);
  for (const PassTime& t : gpu.profile(2, out.result.plan.dt_used))
    out.rows_timed = out.rows_timed || t.name == "contact: rows";
  return out;
}

void expect_same_bits(Context& ctx, uint32_t lanes) {
  const Scene scene =
      parse_scene(phyxel::test::suction_block_json(1000, true, 10000), "block.json");
  const PhyxelSet set = sample_scene(scene);
  const AspirationRun fused = aspirate(ctx, scene, set, true, lanes);
  const AspirationRun apart = aspirate(ctx, scene, set, false, lanes);
  EXPECT_TRUE(fused.rows_timed);
  EXPECT_FALSE(apart.rows_timed);
  ASSERT_TRUE(fused.result.aspirating);
  EXPECT_GE(fused.result.aspiration.events, 1);
  EXPECT_GT(fused.result.aspiration.removed_mass[0], 0);
  EXPECT_EQ(fused.result.aspiration.events, apart.result.aspiration.events);
  EXPECT_EQ(fused.result.aspiration.removed_mass, apart.result.aspiration.removed_mass);
  EXPECT_EQ(fused.state.displacement, apart.state.displacement);
  EXPECT_EQ(fused.state.velocity, apart.state.velocity);
  EXPECT_EQ(fused.state.contact, apart.state.contact);
  ASSERT_EQ(fused.forces.size(), apart.forces.size());
  double largest = 0;
  for (size_t k = 0; k < fused.forces.size(); ++k) {
    EXPECT_EQ(fused.forces[k], apart.forces[k]) << "step " << k;
    largest = std::max(largest, fused.forces[k].norm());
  }
  EXPECT_GT(largest, 0) << "the aspirator felt nothing";
}

TEST_F(GpuSolverTest, ContactInTheForcePassGivesToolContactsBits) {
  expect_same_bits(ctx(), 1);
}

TEST_F(GpuSolverTest, ContactInTheForcePassWithFourLanesGivesToolContactsBits) {
  expect_same_bits(ctx(), 4);
}

}  // namespace
}  // namespace phyxel::gpu::test
