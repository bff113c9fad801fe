// The GPU's largest principal stress (solver_stress's principal mode, tearing) against the CPU
// reference (CpuSolver<double>): for a deformed state at awkward sizes, after loaded steps of a
// damped two-material cantilever, and the stress pass's gather giving it (no pass of its own).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tests/gpu_solver/gpu_solver_fixture.h"

namespace phyxel::gpu::test {
namespace {

std::vector<double> cpu_values(const CpuSolver<double>& cpu) {
  return {cpu.max_principal_stress().begin(), cpu.max_principal_stress().end()};
}

double max_abs(const std::vector<double>& x) {
  double m = 0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

// Every phyxel's value within `tolerance` times the largest magnitude; returns the worst
// difference relative to it.
double expect_close(const std::vector<double>& gpu, const std::vector<double>& cpu,
                    double tolerance, const std::string& what) {
  EXPECT_EQ(gpu.size(), cpu.size()) << what;
  const double scale = max_abs(cpu);
  double worst = 0;
  for (size_t i = 0; i < std::min(gpu.size(), cpu.size()); ++i) {
    EXPECT_TRUE(std::isfinite(gpu[i])) << what << " phyxel " << i;
    EXPECT_NEAR(gpu[i], cpu[i], tolerance * scale) << what << " phyxel " << i;
    worst = std::max(worst, std::abs(gpu[i] - cpu[i]) / scale);
  }
  return worst;
}

TEST_F(GpuSolverTest, PrincipalStressOfADeformedStateMatchesTheCpuAtAwkwardSizes) {
  // One phyxel (no neighbours: no stress), lines (regularised moments) and boxes whose counts
  // are no multiple of the workgroup size.
  const int sizes[][3] = {{1, 1, 1}, {13, 1, 1}, {127, 1, 1}, {7, 5, 3}, {9, 7, 6}};
  for (const auto& n : sizes) {
    const std::string what =
        std::to_string(n[0]) + "x" + std::to_string(n[1]) + "x" + std::to_string(n[2]);
    const PhyxelSet set = lattice(n[0], n[1], n[2], tissue(2e5, 0.35));
    std::vector<Vec3> u, v;
    deformed_state(set, 17, 2e-5, u, v);
    CpuSolver<double> cpu(set, Vec3::Zero());
    for (size_t i = 0; i < set.size(); ++i) cpu.displacement()[i] = u[i];
    cpu.set_principal_stress(true);
    GpuSolver gpu(ctx(), set, Vec3::Zero());
    gpu.set_state(u, v);
    gpu.set_principal_stress(true);
    const std::vector<double> want = cpu_values(cpu);
    const std::vector<double> got = gpu.read_state(true).max_principal_stress;
    if (set.size() == 1) {
      EXPECT_EQ(got, std::vector<double>{0.0});
      EXPECT_EQ(want, std::vector<double>{0.0});
      continue;
    }
    ASSERT_GT(max_abs(want), 1e3) << what;  // a large deformation of a 200 kPa material
    // Float rounding of the gather and of sigma: 2e-6 of the largest value measured on
    // lavapipe, 1.6e-5 on the 127-phyxel line (regularised moments).
    RecordProperty("worst_" + what, std::to_string(expect_close(got, want, 1e-4, what)));
  }
}

TEST_F(GpuSolverTest, RepeatedPrincipalStressesOfHomogeneousStretchesAreExact) {
  // u = (F - I) x: the MLS gradient is F - I at every phyxel (patch test), so sigma is the
  // closed form (F S F^T + k_v (J - 1) J I) / J everywhere, S = lambda' tr(E) I + 2 mu E. The
  // stretches give no stress, a triple principal value (hydrostatic), the largest two equal
  // (equibiaxial: where the plain trigonometric formula loses sqrt(eps), 3e-4, in float), the
  // largest two 1e-6 apart, and the smallest two equal (uniaxial-like).
  const Material m = tissue(1e5, 0.3);
  const PhyxelSet set = lattice(9, 7, 6, m);
  const double kv = volume_stiffness(m), lambda = lame_lambda(m) - kv, mu = lame_mu(m);
  GpuSolver gpu(ctx(), set, Vec3::Zero());
  gpu.set_principal_stress(true);
  const Vec3 centre = set.rest[set.size() / 2];
  for (const Vec3& stretch : {Vec3(1, 1, 1), Vec3(1.01, 1.01, 1.01), Vec3(1.02, 1.02, 0.99),
                              Vec3(1.02, 1.02 + 1e-6, 0.99), Vec3(1.02, 0.99, 0.99)}) {
    std::vector<Vec3> u(set.size()), v(set.size(), Vec3::Zero());
    for (size_t i = 0; i < set.size(); ++i)
      u[i] = (stretch - Vec3::Ones()).cwiseProduct(set.rest[i] - centre);
    gpu.set_state(u, v);
    const Vec3 green = 0.5 * (stretch.cwiseProduct(stretch) - Vec3::Ones());
    const double j = stretch.prod();
    double want = -1e300;
    for (int a = 0; a < 3; ++a)
      want = std::max(want, (stretch[a] * stretch[a] * (lambda * green.sum() + 2 * mu * green[a]) +
                             kv * (j - 1) * j) /
                                j);
    const std::vector<double> got = gpu.read_state(true).max_principal_stress;
    ASSERT_EQ(got.size(), set.size());
    const double scale = std::max(std::abs(want), 1.0);
    for (size_t i = 0; i < set.size(); ++i)
      ASSERT_NEAR(got[i], want, 2e-5 * scale)
          << "stretch " << stretch.transpose() << " phyxel " << i;
  }
}

// A cantilever clamped at x = min, with a stiff inclusion, under gravity and a load pulling its
// free end sideways: stresses of both signs and a non-uniform field.
Scene loaded_cantilever() {
  Scene scene = lattice_scene(16, 5, 5, tissue(1e5, 0.3, 20.0));
  ObjectDesc& o = scene.objects[0];
  // Three layers clamped: the outermost has only fixed neighbours (the stress pass skips it).
  o.fixed.push_back(
      box_shape(Vec3::Constant(-1), Vec3(o.shape.min.x() + 2 * kSpacing + 1e-4, 1, 1)));
  Inclusion inc;
  inc.name = "stiff";
  inc.shape = box_shape(o.shape.min + Vec3(0.015, -1, -1), o.shape.min + Vec3(0.022, 1, 1));
  inc.material = tissue(4e5, 0.45, 20.0);
  inc.material.tear_stress = 5e3;
  o.inclusions.push_back(inc);
  Load load;
  load.region = box_shape(Vec3(o.shape.max.x() - 1e-4, -1, -1), Vec3::Constant(1));
  load.force = Vec3(0.05, 0.1, 0);
  o.loads.push_back(load);
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

TEST_F(GpuSolverTest, PrincipalStressAfterLoadedStepsMatchesTheCpu) {
  const Scene scene = loaded_cantilever();
  ASSERT_TRUE(scene.tearing_possible());
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  CpuSolver<double> cpu(set, scene.simulation.gravity);
  cpu.set_principal_stress(true);
  for (int s = 0; s < 400; ++s) cpu.step(dt);
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  gpu.set_principal_stress(true);
  gpu.advance(150, dt);  // two advances: the values follow the last substep of each
  gpu.advance(250, dt);
  const std::vector<double> want = cpu_values(cpu);
  const std::vector<double> got = gpu.read_state(true).max_principal_stress;
  ASSERT_EQ(gpu.stress_pass_size(), cpu.stress_pass_size());
  ASSERT_LT(cpu.stress_pass_size(), set.size());  // the clamped end's inner layers are skipped
  // Those are unstressed: exactly 0 on both.
  size_t skipped = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    if (want[i] != 0) continue;
    ++skipped;
    EXPECT_EQ(got[i], 0.0) << "phyxel " << i;
  }
  EXPECT_EQ(skipped, set.size() - cpu.stress_pass_size());
  ASSERT_GT(max_abs(want), 100);  // a loaded body, not a few ulps
  // The states differ by float rounding accumulated over 400 steps; the stress, from
  // differences of u, within 2e-4 of its largest value (2.6e-5 measured on lavapipe).
  RecordProperty("worst", std::to_string(expect_close(got, want, 2e-4, "after 400 steps")));
  EXPECT_EQ(gpu.first_non_finite(), -1);
}

// The principal stress rides the stress pass's gather (no pass of its own), and turning it on
// changes none of the elastic step's bits.
TEST_F(GpuSolverTest, PrincipalStressRidesTheStressPass) {
  const Scene scene = loaded_cantilever();
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  GpuSolver gpu(ctx(), set, scene.simulation.gravity);
  GpuSolver plain(ctx(), set, scene.simulation.gravity);
  auto passes = [&] {
    std::vector<std::string> names;
    for (const PassTime& t : gpu.profile(2, dt)) names.push_back(t.name);
    return names;
  };
  const double bytes_off = gpu.bytes_per_phyxel_step();
  EXPECT_TRUE(gpu.read_state(true).max_principal_stress.empty());
  const std::vector<std::string> off = passes();
  plain.advance(2, dt);

  gpu.set_principal_stress(true);
  EXPECT_EQ(passes(), off);  // empty where the device has no timestamps
  plain.advance(2, dt);
  EXPECT_GT(gpu.bytes_per_phyxel_step(), bytes_off);
  const PointState on = gpu.read_state(true);
  ASSERT_EQ(on.max_principal_stress.size(), set.size());
  EXPECT_GT(max_abs(on.max_principal_stress), 0);
  const PointState without = plain.read_state(false);
  EXPECT_EQ(on.displacement, without.displacement);
  EXPECT_EQ(on.velocity, without.velocity);

  gpu.set_principal_stress(false);
  EXPECT_EQ(passes(), off);
  EXPECT_TRUE(gpu.read_state(true).max_principal_stress.empty());
  EXPECT_EQ(gpu.bytes_per_phyxel_step(), bytes_off);
}

}  // namespace
}  // namespace phyxel::gpu::test
