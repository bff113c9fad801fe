// The GPU solver's optional abilities against CpuSolver's semantics: pass lists (fixed-only
// regions skipped, sleeping objects skipped, --no-skip), sleeping and waking, load changes.
#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

// A cantilever along x clamped over its first four layers: the moving phyxels reach one fixed
// layer, so the stress pass skips the three deeper ones (26 neighbours: h = 2 s).
Scene deep_clamp_scene() {
  Scene scene = lattice_scene(12, 5, 4, tissue(1e5, 0.3, 20.0));
  const double x0 = scene.objects[0].shape.min.x();
  scene.objects[0].fixed.push_back(box_shape(Vec3::Constant(-1), Vec3(x0 + 3.5 * kSpacing, 1, 1)));
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

// The deep clamp and a second, free, stiffer object beside it.
Scene two_object_scene() {
  Scene scene = deep_clamp_scene();
  ObjectDesc other = scene.objects[0];
  other.name = "free";
  other.shape.min += Vec3(0, 0.03, 0);
  other.shape.max = other.shape.min + kSpacing * Vec3(5, 4, 3);
  other.material = tissue(2e5, 0.35, 10.0);
  other.fixed.clear();
  scene.objects.push_back(other);
  return scene;
}

size_t count_fixed(const PhyxelSet& set) {
  size_t fixed = 0;
  for (uint32_t f : set.flags) fixed += (f & kFixed) ? 1 : 0;
  return fixed;
}

void expect_same_lists(const GpuSolver& gpu, const CpuSolver<double>& cpu, const char* when) {
  EXPECT_EQ(gpu.force_pass_size(), cpu.force_pass_size()) << when;
  EXPECT_EQ(gpu.stress_pass_size(), cpu.stress_pass_size()) << when;
}

TEST_F(GpuSolverTest, PassListsSkipWhatTheCpuSkips) {
  const Scene scene = two_object_scene();
  const PhyxelSet set = sample_scene(scene);
  ASSERT_EQ(set.objects.size(), 2u);
  const size_t n = set.size(), fixed = count_fixed(set);
  ASSERT_EQ(fixed, 4u * 5 * 4);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  CpuSolver<double> cpu(set, scene.simulation.gravity);
  EXPECT_NE(gpu.pass_selection(), nullptr);
  EXPECT_NE(gpu.load_changes(), nullptr);
  EXPECT_TRUE(gpu.pass_selection_on());
  // Selection on: the moving phyxels, and for the stress pass one fixed layer more.
  EXPECT_EQ(gpu.force_pass_size(), n - fixed);
  EXPECT_EQ(gpu.stress_pass_size(), n - fixed + 5 * 4);
  expect_same_lists(gpu, cpu, "selection on");
  // The free object asleep: only the cantilever's passes are left.
  gpu.set_object_awake(1, false);
  cpu.set_object_awake(1, false);
  EXPECT_FALSE(gpu.object_awake(1));
  EXPECT_EQ(gpu.force_pass_size(), set.objects[0].count - fixed);
  expect_same_lists(gpu, cpu, "object 1 asleep");
  gpu.set_object_awake(0, false);
  cpu.set_object_awake(0, false);
  EXPECT_EQ(gpu.force_pass_size(), 0u);
  EXPECT_EQ(gpu.stress_pass_size(), 0u);
  expect_same_lists(gpu, cpu, "both asleep");
  // Selection off (--no-skip) and both awake: every pass over every phyxel.
  gpu.set_pass_selection(false);
  cpu.set_pass_selection(false);
  gpu.set_object_awake(0, true);
  cpu.set_object_awake(0, true);
  gpu.set_object_awake(1, true);
  cpu.set_object_awake(1, true);
  EXPECT_EQ(gpu.force_pass_size(), n);
  EXPECT_EQ(gpu.stress_pass_size(), n);
  expect_same_lists(gpu, cpu, "selection off");
  EXPECT_THROW(gpu.set_object_awake(2, false), std::out_of_range);
}

TEST_F(GpuSolverTest, NoSkipGivesBitIdenticalMotionAndReactionsOnFixedPhyxels) {
  const Scene scene = deep_clamp_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  GpuSolver skip(ctx(), set, scene.simulation.gravity);
  GpuSolver all(ctx(), set, scene.simulation.gravity);
  all.set_pass_selection(false);
  // Across two submits, and a fused step split over advance() calls.
  for (GpuSolver* s : {&skip, &all}) {
    s->advance(1, dt);
    s->advance(299, dt);
  }
  const PointState a = skip.read_state(false);
  const PointState b = all.read_state(false);
  const std::vector<Vec3> fa = skip.forces();
  const std::vector<Vec3> fb = all.forces();
  double reaction = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    if (set.flags[i] & kFixed) {
      EXPECT_EQ(a.displacement[i], Vec3::Zero()) << "phyxel " << i;
      EXPECT_EQ(b.displacement[i], Vec3::Zero()) << "phyxel " << i;
      EXPECT_EQ(fa[i], Vec3::Zero()) << "phyxel " << i;  // not in the force pass
      reaction = std::max(reaction, fb[i].norm());
      continue;
    }
    ASSERT_EQ(a.displacement[i], b.displacement[i]) << "phyxel " << i;
    ASSERT_EQ(a.velocity[i], b.velocity[i]) << "phyxel " << i;
    ASSERT_EQ(fa[i], fb[i]) << "phyxel " << i;
  }
  EXPECT_GT(max_norm(a.displacement), 1e-3 * extent(set));  // it sags
  EXPECT_GT(reaction, 0);                                   // --no-skip: the clamp carries the beam
  const Energies ea = skip.energies(), eb = all.energies();
  EXPECT_EQ(ea.strain, eb.strain);
  EXPECT_EQ(ea.kinetic, eb.kinetic);
  EXPECT_EQ(ea.potential, eb.potential);
}

// A removal updates the pass lists in place: the first moving layer next to the clamp goes, and
// the fixed layer it alone reached leaves the stress pass: the lists and the steps after it are
// those of a solver whose lists were rebuilt from scratch, bit for bit.
TEST_F(GpuSolverTest, RemovalUpdatesThePassListsAsAFullRebuild) {
  const Scene scene = deep_clamp_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  double x0 = set.rest[0].x();
  for (const Vec3& x : set.rest) x0 = std::min(x0, x.x());
  const double layer_x = x0 + 4 * kSpacing;  // the first moving layer
  std::vector<uint32_t> ids;
  for (uint32_t i = 0; i < set.size(); ++i)
    if (std::abs(set.rest[i].x() - layer_x) < 0.25 * kSpacing) ids.push_back(i);
  ASSERT_EQ(ids.size(), 5u * 4);
  GpuSolver updated(ctx(), set, scene.simulation.gravity);
  GpuSolver rebuilt(ctx(), set, scene.simulation.gravity);
  const size_t stress_before = updated.stress_pass_size();
  for (GpuSolver* s : {&updated, &rebuilt}) {
    s->advance(20, dt);
    s->remove_phyxels(ids);
  }
  rebuilt.set_pass_selection(true);  // the lists built again from the flags and the CSR
  EXPECT_EQ(updated.stress_pass_size(), stress_before - 2 * 5 * 4);  // the layer and the fixed one
  EXPECT_EQ(updated.force_pass_size(), rebuilt.force_pass_size());
  EXPECT_EQ(updated.stress_pass_size(), rebuilt.stress_pass_size());
  updated.remove_phyxels({ids[1], ids[1]});  // already removed: nothing changes
  EXPECT_EQ(updated.stress_pass_size(), rebuilt.stress_pass_size());
  updated.advance(40, dt);
  rebuilt.advance(40, dt);
  const PointState a = updated.read_state(false), b = rebuilt.read_state(false);
  EXPECT_EQ(a.displacement, b.displacement);
  EXPECT_EQ(a.velocity, b.velocity);
  EXPECT_GT(max_norm(a.displacement), 0.0);
}

TEST_F(GpuSolverTest, ADisplacedClampStaysDisplacedOutsideThePassLists) {
  // u set by hand on fixed phyxels (a moved clamp): the step passes never write it, in either
  // displacement buffer, yet every step must read it.
  const Scene scene = deep_clamp_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const Eigen::Matrix3d g = Eigen::Vector3d(0.01, -0.005, 0.003).asDiagonal();
  std::vector<Vec3> u(set.size()), v(set.size(), Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i) u[i] = g * (set.rest[i] - set.rest[0]) + Vec3(0, 0, 1e-4);
  for (const bool select : {true, false}) {
    GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    CpuSolver<double> cpu(set, scene.simulation.gravity);
    gpu.set_pass_selection(select);
    cpu.set_pass_selection(select);
    gpu.set_state(u, v);
    const PointState start = gpu.read_state(false);
    cpu.displacement().assign(u.begin(), u.end());
    cpu.compute_forces();
    // An even and an odd number of steps: u of a step lands in either buffer.
    gpu.advance(2, dt);
    gpu.advance(3, dt);
    for (int s = 0; s < 5; ++s) cpu.step(dt);
    const PointState st = gpu.read_state(false);
    const std::vector<Vec3> uc(cpu.displacement().begin(), cpu.displacement().end());
    std::vector<Vec3> du_gpu(set.size()), du_cpu(set.size());
    for (size_t i = 0; i < set.size(); ++i) {
      if (set.flags[i] & kFixed) {
        ASSERT_EQ(st.displacement[i], start.displacement[i]) << "phyxel " << i;
      }
      du_gpu[i] = st.displacement[i] - u[i];
      du_cpu[i] = uc[i] - u[i];
    }
    EXPECT_LE(max_difference(du_gpu, du_cpu), 1e-4 * max_norm(du_cpu) + 1e-7 * max_norm(u))
        << (select ? "selection on" : "selection off");
  }
}

TEST_F(GpuSolverTest, SleepingStopsAnObjectAndWakingRecomputesItsForces) {
  const Scene scene = two_object_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  const ObjectRange& sleeper = set.objects[1];
  auto in_sleeper = [&](size_t i) { return set.object[i] == 1; };
  // The free object stretched a little and moving, the cantilever at rest.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-1, 1);
  const Eigen::Matrix3d g = Eigen::Vector3d(0.02, -0.01, 0.01).asDiagonal();
  std::vector<Vec3> u(set.size(), Vec3::Zero()), v(set.size(), Vec3::Zero());
  for (uint32_t i = sleeper.first; i < sleeper.first + sleeper.count; ++i) {
    u[i] = g * (set.rest[i] - set.rest[sleeper.first]) + 1e-6 * Vec3(d(rng), d(rng), d(rng));
    v[i] = 0.01 * Vec3(d(rng), d(rng), d(rng));
  }
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  gpu.set_state(u, v);
  CpuSolver<double> cpu(set, scene.simulation.gravity);
  cpu.displacement().assign(u.begin(), u.end());
  cpu.velocity().assign(v.begin(), v.end());
  cpu.compute_forces();

  gpu.set_object_awake(1, false);
  cpu.set_object_awake(1, false);
  const PointState asleep = gpu.read_state(false);
  for (uint32_t i = sleeper.first; i < sleeper.first + sleeper.count; ++i)
    ASSERT_EQ(asleep.velocity[i], Vec3::Zero()) << "phyxel " << i;
  gpu.advance(100, dt);
  for (int s = 0; s < 100; ++s) cpu.step(dt);
  const PointState slept = gpu.read_state(false);
  std::vector<Vec3> uc(cpu.displacement().begin(), cpu.displacement().end());
  double moved = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    if (in_sleeper(i)) {
      ASSERT_EQ(slept.displacement[i], asleep.displacement[i]) << "phyxel " << i;
      ASSERT_EQ(slept.velocity[i], Vec3::Zero()) << "phyxel " << i;
    } else {
      moved = std::max(moved, slept.displacement[i].norm());
    }
  }
  EXPECT_GT(moved, 0);  // the awake cantilever went on sagging
  EXPECT_LE(max_difference(slept.displacement, uc), 1e-4 * max_norm(uc));

  // A load reaches the sleeper while it sleeps (as in run_simulation: loads first, then the
  // wake): its forces are recomputed only when it wakes.
  std::vector<Vec3> loads(set.size(), Vec3::Zero());
  const double top = set.rest[sleeper.first + sleeper.count - 1].z() - 1e-4;
  for (uint32_t i = sleeper.first; i < sleeper.first + sleeper.count; ++i)
    if (set.rest[i].z() > top) loads[i] = Vec3(0, 0.01, 0);
  gpu.set_external_forces(loads);
  cpu.set_external_forces(loads);
  gpu.set_object_awake(1, true);
  cpu.set_object_awake(1, true);
  const std::vector<Vec3> fg = gpu.forces();
  const std::vector<Vec3> fc(cpu.force().begin(), cpu.force().end());
  const double f_scale = max_norm(fc);
  ASSERT_GT(f_scale, 0.005);  // the load is a large part of it
  for (uint32_t i = sleeper.first; i < sleeper.first + sleeper.count; ++i)
    EXPECT_LE((fg[i] - fc[i]).norm(), 1e-4 * f_scale) << "phyxel " << i;
  gpu.advance(100, dt);
  for (int s = 0; s < 100; ++s) cpu.step(dt);
  uc.assign(cpu.displacement().begin(), cpu.displacement().end());
  const PointState woken = gpu.read_state(false);
  EXPECT_LE(max_difference(woken.displacement, uc), 1e-4 * max_norm(uc));
  double sleeper_moved = 0;
  for (uint32_t i = sleeper.first; i < sleeper.first + sleeper.count; ++i)
    sleeper_moved = std::max(sleeper_moved, (woken.displacement[i] - slept.displacement[i]).norm());
  EXPECT_GT(sleeper_moved, 1e-3 * max_norm(uc));
}

TEST_F(GpuSolverTest, ChangedLoadsMatchTheCpu) {
  const Scene scene = deep_clamp_scene();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  CpuSolver<double> cpu(set, scene.simulation.gravity);
  gpu.advance(100, dt);
  for (int s = 0; s < 100; ++s) cpu.step(dt);
  // Push the free end sideways and up (0.02 N in all), gravity stays.
  std::vector<Vec3> loads(set.size(), Vec3::Zero());
  const double x_end = scene.objects[0].shape.max.x() - 1e-4;
  size_t loaded = 0;
  for (size_t i = 0; i < set.size(); ++i) loaded += set.rest[i].x() > x_end ? 1 : 0;
  ASSERT_EQ(loaded, 20u);
  for (size_t i = 0; i < set.size(); ++i)
    if (set.rest[i].x() > x_end) loads[i] = Vec3(0, 0.02, 0.01) / double(loaded);
  gpu.set_external_forces(loads);
  cpu.set_external_forces(loads);
  // The forces of the current state with the new loads, right away.
  const std::vector<Vec3> fg = gpu.forces();
  const std::vector<Vec3> fc(cpu.force().begin(), cpu.force().end());
  EXPECT_LE(max_difference(fg, fc), 1e-4 * max_norm(fc));
  EXPECT_NEAR(gpu.energies().potential, cpu.energies().potential,
              1e-4 * std::abs(cpu.energies().potential));
  // And the motion they drive.
  gpu.advance(600, dt);
  for (int s = 0; s < 600; ++s) cpu.step(dt);
  const PointState g = gpu.read_state(false);
  const std::vector<Vec3> uc(cpu.displacement().begin(), cpu.displacement().end());
  double sideways = 0;
  for (const Vec3& x : uc) sideways = std::max(sideways, x.y());
  EXPECT_GT(sideways, 0.1 * max_norm(uc));  // the load, not gravity alone, shaped it
  EXPECT_LE(max_difference(g.displacement, uc), 1e-4 * max_norm(uc));
  EXPECT_THROW(gpu.set_external_forces(std::vector<Vec3>(3)), std::invalid_argument);
}

}  // namespace
}  // namespace phyxel::gpu::test
