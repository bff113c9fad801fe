// Several invocations per phyxel in the gathering passes (GpuSolverOptions::lanes): every
// lane count gives the one-lane step to float rounding (forces, a run of steps, the largest
// principal stress), on sets that exercise the pass lists (a clamp), regularised moment
// matrices (a plate) and two materials; a rerun with lanes is bit-identical; bad counts are
// refused.
#include <stdexcept>

#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// A clamped two-material block under gravity (the force list skips the clamp), and a plate
// one phyxel thick (every moment matrix regularised).
std::vector<std::pair<const char*, Scene>> lane_scenes() {
  Scene block = two_material_scene();
  block.objects[0].fixed.push_back(
      box_shape(Vec3::Constant(-1), Vec3(block.objects[0].shape.min.x() + 1e-4, 1, 1)));
  // Thinner than the spacing: one layer with a volume (mls_properties_test.cpp).
  Scene plate =
      box_scene(Vec3(0, 0, 0), Vec3(0.015, 0.0125, 0.001), kSpacing, tissue(1e5, 0.3, 2.0));
  plate.simulation.gravity = Vec3(0, -9.81, 0);
  return {{"block", block}, {"plate", plate}};
}

struct LaneRun {
  std::vector<Vec3> forces;
  PointState state;
};

LaneRun run_with_lanes(Context& ctx, const Scene& scene, const PhyxelSet& set, uint32_t lanes,
                       const std::vector<int64_t>& chunks) {
  GpuSolverOptions options;
  options.lanes = lanes;
  GpuSolver gpu(ctx, set, scene.simulation.gravity, options);
  const auto n = static_cast<uint32_t>(set.size());
  EXPECT_EQ(gpu.lanes_for(GpuSolver::Gather::Stress, n), lanes);
  EXPECT_EQ(gpu.lanes_for(GpuSolver::Gather::Force, n), lanes);
  std::vector<Vec3> u, v;
  deformed_state(set, 11, 1e-5, u, v);
  gpu.set_principal_stress(true);
  gpu.set_state(u, v);
  LaneRun run;
  run.forces = gpu.forces();
  const double dt = plan_time_step(scene, set).dt_stable;
  for (const int64_t n : chunks) gpu.advance(n, dt);
  run.state = gpu.read_state(true);
  return run;
}

double max_abs(const std::vector<double>& x) {
  double m = 0;
  for (const double v : x) m = std::max(m, std::abs(v));
  return m;
}

TEST_F(GpuSolverTest, EveryLaneCountGivesTheOneLaneStepToRounding) {
  for (const auto& [name, scene] : lane_scenes()) {
    SCOPED_TRACE(name);
    const PhyxelSet set = sample_scene(scene, SamplingOptions{false});
    const LaneRun one = run_with_lanes(ctx(), scene, set, 1, {40});
    const double f_scale = max_norm(one.forces);
    const double u_scale = max_norm(one.state.displacement);
    const double v_scale = max_norm(one.state.velocity);
    const double s_scale = max_abs(one.state.max_principal_stress);
    ASSERT_GT(f_scale, 0);
    ASSERT_GT(v_scale, 0);
    ASSERT_GT(s_scale, 0);
    for (const uint32_t lanes : {2u, 4u, 8u, 16u}) {
      SCOPED_TRACE(lanes);
      const LaneRun r = run_with_lanes(ctx(), scene, set, lanes, {40});
      EXPECT_LE(max_difference(r.forces, one.forces), 1e-5 * f_scale);
      EXPECT_LE(max_difference(r.state.displacement, one.state.displacement), 1e-5 * u_scale);
      EXPECT_LE(max_difference(r.state.velocity, one.state.velocity), 1e-4 * v_scale);
      double s_err = 0;
      for (size_t i = 0; i < set.size(); ++i)
        s_err = std::max(
            s_err, std::abs(r.state.max_principal_stress[i] - one.state.max_principal_stress[i]));
      EXPECT_LE(s_err, 1e-4 * s_scale);
    }
  }
}

TEST_F(GpuSolverTest, RunsWithLanesAreBitIdenticalHoweverTheStepsAreSplit) {
  const Scene scene = lane_scenes()[0].second;
  const PhyxelSet set = sample_scene(scene, SamplingOptions{false});
  const LaneRun a = run_with_lanes(ctx(), scene, set, 8, {60});
  const LaneRun b = run_with_lanes(ctx(), scene, set, 8, {1, 33, 26});
  for (size_t i = 0; i < set.size(); ++i) {
    ASSERT_EQ(a.state.displacement[i], b.state.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(a.state.velocity[i], b.state.velocity[i]) << "phyxel " << i;
    ASSERT_EQ(a.state.max_principal_stress[i], b.state.max_principal_stress[i]) << "phyxel " << i;
  }
  EXPECT_GT(max_norm(a.state.velocity), 0);
}

TEST_F(GpuSolverTest, LaneCountsThatAreNotPowersOfTwoUpTo16AreRefused) {
  const PhyxelSet set = lattice(4, 4, 4);
  for (const uint32_t lanes : {3u, 6u, 32u}) {
    GpuSolverOptions options;
    options.lanes = lanes;
    EXPECT_THROW(GpuSolver(ctx(), set, Vec3::Zero(), options), std::invalid_argument) << lanes;
  }
  // Auto: one lane on a CPU device (lavapipe), where lanes only add work.
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  using Gather = GpuSolver::Gather;
  if (ctx().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    for (const uint32_t n : {64u, 5000u, 1000000u}) {
      EXPECT_EQ(gpu.lanes_for(Gather::Stress, n), 1u);
      EXPECT_EQ(gpu.lanes_for(Gather::Force, n), 1u);
    }
  } else {
    EXPECT_EQ(gpu.lanes_for(Gather::Stress, 5000), 8u);
    EXPECT_EQ(gpu.lanes_for(Gather::Force, 5000), 16u);
    EXPECT_EQ(gpu.lanes_for(Gather::Stress, 100000), 1u);
    EXPECT_EQ(gpu.lanes_for(Gather::Force, 100000), 1u);
    EXPECT_EQ(gpu.lanes_for(Gather::Stress, 1000000), 1u);
    EXPECT_EQ(gpu.lanes_for(Gather::Force, 1000000), 2u);
  }
}

}  // namespace
}  // namespace phyxel::gpu::test
