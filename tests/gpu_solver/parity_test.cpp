// The GPU solver against the CPU reference (CpuSolver<double>): forces and energies of a
// deformed state, one step, 1000 damped steps, and bit-identical repeat runs.
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// A cantilever clamped at x = min under gravity, damped: it sags a few percent of its length.
Scene cantilever_scene() {
  Scene scene = lattice_scene(16, 5, 5, tissue(1e5, 0.3, 20.0));
  Shape clamp = box_shape(Vec3::Constant(-1), Vec3(scene.objects[0].shape.min.x() + 1e-4, 1, 1));
  scene.objects[0].fixed.push_back(clamp);
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

TEST_F(GpuSolverTest, ForcesEnergiesAndOneStepMatchTheCpu) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene);
  ASSERT_GE(set.materials.size(), 2u);
  const double dt = plan_time_step(scene, set).dt_stable;
  std::vector<Vec3> u, v;
  deformed_state(set, 5, 2e-5, u, v);

  CpuSolver<double> cpu(set, scene.simulation.gravity);
  for (size_t i = 0; i < set.size(); ++i) {
    cpu.displacement()[i] = u[i];
    cpu.velocity()[i] = v[i];
  }
  cpu.compute_forces();
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  gpu.set_state(u, v);

  // Forces: float32 sums of ~26 terms that largely cancel.
  const std::vector<Vec3> f = gpu.forces();
  const double f_scale = max_norm(std::vector<Vec3>(cpu.force().begin(), cpu.force().end()));
  ASSERT_GT(f_scale, 0);
  EXPECT_LE(max_difference(f, cpu.force()), 1e-4 * f_scale);

  const Energies eg = gpu.energies();
  const Energies ec = cpu.energies();
  ASSERT_GT(ec.strain, 0);
  EXPECT_NEAR(eg.strain, ec.strain, 1e-4 * ec.strain);
  EXPECT_NEAR(eg.kinetic, ec.kinetic, 1e-5 * ec.kinetic);
  EXPECT_NEAR(eg.potential, ec.potential, 1e-5 * std::abs(ec.potential));

  const std::vector<double> vm_cpu = cpu.von_mises_stress();
  const std::vector<double> vm_gpu = gpu.read_state(true).von_mises;
  ASSERT_EQ(vm_gpu.size(), set.size());
  const double vm_scale = *std::max_element(vm_cpu.begin(), vm_cpu.end());
  for (size_t i = 0; i < set.size(); ++i)
    EXPECT_NEAR(vm_gpu[i], vm_cpu[i], 1e-4 * vm_scale) << "phyxel " << i;

  // One step: u to 1e-5 of its size, and the step's change of u and v to 1e-4 of theirs (u's
  // change also within the float32 rounding of u itself, about 1e-7 of its size).
  cpu.step(dt);
  gpu.advance(1, dt);
  const PointState s = gpu.read_state(false);
  const std::vector<Vec3> uc(cpu.displacement().begin(), cpu.displacement().end());
  const std::vector<Vec3> vc(cpu.velocity().begin(), cpu.velocity().end());
  EXPECT_LE(max_difference(s.displacement, uc), 1e-5 * max_norm(uc));
  std::vector<Vec3> du_cpu(set.size()), du_gpu(set.size()), dv_cpu(set.size()), dv_gpu(set.size());
  for (size_t i = 0; i < set.size(); ++i) {
    du_cpu[i] = uc[i] - u[i];
    du_gpu[i] = s.displacement[i] - u[i];
    dv_cpu[i] = vc[i] - v[i];
    dv_gpu[i] = s.velocity[i] - v[i];
  }
  EXPECT_LE(max_difference(du_gpu, du_cpu), 1e-4 * max_norm(du_cpu) + 1e-7 * max_norm(uc));
  EXPECT_LE(max_difference(dv_gpu, dv_cpu), 1e-4 * max_norm(dv_cpu));
}

TEST_F(GpuSolverTest, ThousandDampedStepsStayWithinATenthOfAPerMilleOfTheExtent) {
  const Scene scene = cantilever_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  CpuSolver<double> cpu(set, scene.simulation.gravity);
  for (int s = 0; s < 1000; ++s) cpu.step(dt);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  gpu.advance(1000, dt);
  const PointState g = gpu.read_state(false);
  const std::vector<Vec3> uc(cpu.displacement().begin(), cpu.displacement().end());
  const double sag = max_norm(uc);
  ASSERT_GT(sag, 0.02 * extent(set));  // a real deflection, not a few ulps
  EXPECT_LE(max_difference(g.displacement, uc), 1e-3 * extent(set));
  EXPECT_LE(max_difference(g.displacement, uc), 1e-3 * sag);
  EXPECT_EQ(gpu.first_non_finite(), -1);
}

TEST_F(GpuSolverTest, RunsAreBitIdenticalHoweverTheStepsAreSplit) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  std::vector<Vec3> u, v;
  deformed_state(set, 9, 1e-5, u, v);
  auto run = [&](const std::vector<int64_t>& chunks) {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    gpu.set_state(u, v);
    for (int64_t n : chunks) gpu.advance(n, dt);
    return gpu.read_state(false);
  };
  // 300 steps in one advance (ten submissions of 8 to 90 steps), again, and in three uneven parts
  // (the step passes fuse a step's closing kick with the next step's opening kick and drift
  // only inside one advance).
  const PointState a = run({300});
  const PointState b = run({300});
  const PointState c = run({1, 120, 179});
  for (const PointState* other : {&b, &c}) {
    ASSERT_EQ(other->displacement.size(), a.displacement.size());
    for (size_t i = 0; i < set.size(); ++i) {
      ASSERT_EQ(other->displacement[i], a.displacement[i]) << "phyxel " << i;
      ASSERT_EQ(other->velocity[i], a.velocity[i]) << "phyxel " << i;
    }
  }
  EXPECT_GT(max_norm(a.velocity), 0);
}

TEST_F(GpuSolverTest, RecomputedAndStoredPairWeightsGiveTheSameForces) {
  const Scene scene = two_material_scene();
  const PhyxelSet set = sample_scene(scene);
  std::vector<Vec3> u, v;
  deformed_state(set, 3, 2e-5, u, v);
  GpuSolver recomputed(ctx(), set, scene.simulation.gravity);  // PairWeights::Auto
  GpuSolverOptions options;
  options.pair_weights = GpuSolverOptions::PairWeights::Stored;
  GpuSolver stored(ctx(), set, scene.simulation.gravity, options);
  stored.set_state(u, v);
  recomputed.set_state(u, v);
  const std::vector<Vec3> fs = stored.forces();
  EXPECT_LE(max_difference(recomputed.forces(), fs), 1e-5 * max_norm(fs));
  EXPECT_NEAR(recomputed.energies().strain, stored.energies().strain,
              1e-5 * stored.energies().strain);
  EXPECT_LT(recomputed.bytes_per_phyxel_step(), stored.bytes_per_phyxel_step());
}

}  // namespace
}  // namespace phyxel::gpu::test
