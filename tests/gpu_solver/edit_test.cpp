// Deactivating phyxels in place (the buffers' design for cutting): the result equals a solver
// built without them, and the CPU reference on that set.
#include <algorithm>
#include <string>

#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

TEST_F(GpuSolverTest, RemovingPhyxelsInPlaceEqualsASetWithoutThem) {
  Scene scene = lattice_scene(8, 6, 5, tissue(2e5, 0.3, 10.0));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  const PhyxelSet full = sample_scene(scene);
  // An interior phyxel, a face phyxel and a corner.
  const std::vector<uint32_t> ids = {2 * 48 + 2 * 8 + 3, 8 + 5, 0};
  PhyxelSet cut = full;
  for (uint32_t i : ids) cut.flags[i] |= kRemoved;
  const double dt = plan_time_step(scene, full).dt_stable;

  GpuSolver edited(ctx(), full, scene.simulation.gravity);
  edited.remove_phyxels(ids);
  GpuSolver rebuilt(ctx(), cut, scene.simulation.gravity);
  EXPECT_EQ(edited.regularised_count(), rebuilt.regularised_count());
  // Removed phyxels leave every pass (their zero-weight pairs add nothing to the stress pass).
  EXPECT_EQ(edited.force_pass_size(), full.size() - ids.size());
  EXPECT_EQ(edited.force_pass_size(), rebuilt.force_pass_size());
  EXPECT_EQ(edited.stress_pass_size(), rebuilt.stress_pass_size());

  // The same moment inverses for every phyxel (the removed ones have none).
  const std::vector<MomentInverseRow> a = edited.moment_inverses();
  const std::vector<MomentInverseRow> b = rebuilt.moment_inverses();
  for (size_t i = 0; i < full.size(); ++i) {
    EXPECT_EQ(a[i].regularised, b[i].regularised) << "phyxel " << i;
    for (int c = 0; c < 6; ++c)
      EXPECT_NEAR(a[i].inverse[c], b[i].inverse[c], 1e-6 * std::abs(b[i].inverse[0]) + 1e-30)
          << "phyxel " << i;
  }

  // The same forces for a deformed state, and the CPU's on the cut set.
  std::vector<Vec3> u, v;
  deformed_state(full, 21, 2e-5, u, v);
  edited.set_state(u, v);
  rebuilt.set_state(u, v);
  CpuSolver<double> cpu(cut, scene.simulation.gravity);
  for (size_t i = 0; i < full.size(); ++i) {
    cpu.displacement()[i] = u[i];
    cpu.velocity()[i] = v[i];
  }
  cpu.compute_forces();
  EXPECT_EQ(edited.stress_pass_size(), cpu.stress_pass_size());
  EXPECT_EQ(edited.force_pass_size(), cpu.force_pass_size());
  // Forces exist only for phyxels in the force pass (pass selection, on both solvers); a
  // removed phyxel keeps its last one (edited) or none (rebuilt, and the CPU).
  std::vector<Vec3> fe = edited.forces(), fr = rebuilt.forces();
  std::vector<Vec3> fc(cpu.force().begin(), cpu.force().end());
  for (uint32_t i : ids) {
    EXPECT_EQ(fr[i], Vec3::Zero()) << "phyxel " << i;
    fc[i] = fe[i] = Vec3::Zero();
  }
  const double scale = max_norm(fc);
  EXPECT_LE(max_difference(fe, fr), 1e-6 * scale);
  EXPECT_LE(max_difference(fe, fc), 1e-4 * scale);

  // And the same motion; the removed phyxels stay where they were.
  const PointState before = edited.read_state(false);
  edited.advance(50, dt);
  rebuilt.advance(50, dt);
  const PointState se = edited.read_state(false);
  const PointState sr = rebuilt.read_state(false);
  EXPECT_LE(max_difference(se.displacement, sr.displacement), 1e-5 * max_norm(sr.displacement));
  for (uint32_t i : ids) EXPECT_EQ(se.displacement[i], before.displacement[i]) << "phyxel " << i;
  EXPECT_NEAR(edited.energies().strain, rebuilt.energies().strain,
              1e-4 * rebuilt.energies().strain);
}

}  // namespace
}  // namespace phyxel::gpu::test
