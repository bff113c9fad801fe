// Numerical stability stress tests (quick ones; `phyxel bench --stability` runs the long
// soaks): time steps around the stable bound, extreme stretch and compression, near-inversion,
// sparse neighbourhoods, float against double, and clean stops.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

Scene cube(double poisson = 0.3, double h_factor = 2.0, double damping = 0) {
  return test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.02), 0.0025,
                         test::tissue(1e5, poisson, damping), h_factor);
}

// Largest relative error of the total energy in the first and second half of a run of
// `steps` steps of dt from the initial deformation u = g x (no damping, no load).
struct Drift {
  double first = 0, second = 0;
};

Drift energy_drift(const PhyxelSet& set, const Eigen::Matrix3d& g, double dt, int steps) {
  CpuSolver<double> solver(set, Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i) solver.displacement()[i] = g * set.rest[i];
  solver.compute_forces();
  const double e0 = solver.energies().total();
  Drift d;
  for (int k = 1; k <= steps; ++k) {
    solver.step(dt);
    if (k % 20 == 0) {
      if (solver.first_non_finite() >= 0) {
        ADD_FAILURE() << "non-finite at step " << k;
        return {1e300, 1e300};
      }
      double& half = k <= steps / 2 ? d.first : d.second;
      half = std::max(half, std::abs(solver.energies().total() - e0) / e0);
    }
  }
  return d;
}

// Velocity Verlet's energy error oscillates with amplitude ~ (omega dt)^2 and does not grow:
// the bounds documented in docs/performance.md, and the second half no worse than the first.
void expect_bounded(const Drift& d, double bound, const std::string& what) {
  EXPECT_LT(d.first, bound) << what;
  EXPECT_LT(d.second, 1.2 * d.first + 1e-4) << what << ": energy error grows";
}

TEST(Stability, StepsUpToTheBoundStayFiniteWithBoundedEnergyError) {
  const Scene scene = cube();
  const PhyxelSet set = sample_scene(scene);
  const double bound = plan_time_step(scene, set).dt_stable;
  const Eigen::Matrix3d stretch = Eigen::Vector3d(0.05, -0.02, 0.01).asDiagonal();
  for (const auto& [fraction, limit] :
       {std::pair{0.1, 0.002}, {0.25, 0.005}, {0.5, 0.02}, {1.0, 0.08}})
    expect_bounded(energy_drift(set, stretch, fraction * bound, 2000), limit,
                   "dt = " + std::to_string(fraction) + " x bound");
}

TEST(Stability, StepsAboveTheBoundAreSubsteppedNeverUsedAsIs) {
  Scene scene = cube();
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001)));
  const PhyxelSet set = sample_scene(scene);
  const double bound = plan_time_step(scene, set).dt_stable;
  for (double fraction : {1.2, 2.0}) {
    scene.simulation.dt = fraction * bound;
    const TimeStepPlan plan = plan_time_step(scene, set);
    EXPECT_LE(plan.dt_used, bound * (1 + 1e-12));
    EXPECT_EQ(plan.substeps, 2);
    auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    RunOptions options;
    options.steps = 2000;
    const RunResult r = run_simulation(scene, set, *solver, options);
    EXPECT_FALSE(r.non_finite);
    EXPECT_FALSE(r.unstable);
    EXPECT_EQ(r.steps_done, 2000);
  }
}

TEST(Stability, FiftyPercentStretchAndCompressionNearIncompressible) {
  for (double poisson : {0.3, 0.45, 0.49}) {
    const Scene scene = cube(poisson);
    const PhyxelSet set = sample_scene(scene);
    const double dt = 0.5 * plan_time_step(scene, set).dt_stable;
    for (double strain : {0.5, -0.5}) {
      const Eigen::Matrix3d g = Eigen::Vector3d(strain, 0, 0).asDiagonal();
      expect_bounded(energy_drift(set, g, dt, 2000), 0.02,
                     "nu " + std::to_string(poisson) + " strain " + std::to_string(strain));
    }
  }
}

TEST(Stability, NearInversionIsPushedBackByTheVolumeTerm) {
  // Squashed to 10 % of its height (J = 0.1): St Venant-Kirchhoff alone softens here; the
  // volume term makes the cube spring back, and nothing becomes non-finite.
  const Scene scene = cube(0.45, 2.0, 50);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i)
    solver.displacement()[i] = Vec3(0, 0, -0.9 * set.rest[i].z());
  solver.compute_forces();
  const double dt = plan_time_step(scene, set).dt_stable;
  for (int k = 0; k < 3000; ++k) solver.step(dt);
  ASSERT_LT(solver.first_non_finite(), 0);
  // Height recovered: the top layer is back above half its rest height.
  double top = 0;
  for (size_t i = 0; i < set.size(); ++i)
    top = std::max(top, set.rest[i].z() + solver.displacement()[i].z());
  EXPECT_GT(top, 0.01);
}

TEST(Stability, MinimumSupportRadiusStaysFinite) {
  // Support radius just above sqrt(2) s (the smallest the scene reader accepts).
  Scene scene = cube(0.3, 1.42, 20);
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001)));
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  RunOptions options;
  options.steps = 3000;
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_FALSE(r.non_finite);
  EXPECT_FALSE(r.unstable);
}

TEST(Stability, FloatTracksDoubleOverAThousandSteps) {
  Scene scene = cube(0.3, 2.0, 20);
  scene.objects[0].fixed.push_back(test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001)));
  const PhyxelSet set = sample_scene(scene);
  const double dt = plan_time_step(scene, set).dt_stable;
  CpuSolver<double> d(set, Vec3(0, 0, -9.81));
  CpuSolver<float> f(set, Vec3(0, 0, -9.81));
  double scale = 0, diff = 0;
  for (int k = 0; k < 1000; ++k) {
    d.step(dt);
    f.step(float(dt));
  }
  for (size_t i = 0; i < set.size(); ++i) {
    scale = std::max(scale, d.displacement()[i].norm());
    diff = std::max(diff, (d.displacement()[i] - f.displacement()[i].cast<double>()).norm());
  }
  ASSERT_GT(scale, 0);
  EXPECT_LT(diff, 1e-3 * 0.02);  // 1e-3 of the object's extent
  EXPECT_LT(diff / scale, 1e-3);
}

TEST(Stability, RunawayMotionIsStoppedAndExplainedBeforeItTurnsNonFinite) {
  // A huge load on a free cube: phyxels soon move faster than sound in the material, which no
  // elastic tissue does. The run stops with the step and phyxel instead of producing NaN.
  Scene scene = cube();
  Load kick;
  kick.region = test::box_shape(Vec3(-1, -1, -1), Vec3(1, 1, 0.001));
  kick.force = Vec3(0, 0, -1e6);
  scene.objects[0].loads.push_back(kick);
  const PhyxelSet set = sample_scene(scene);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  auto solver = make_cpu_solver(set, Vec3::Zero(), 1);
  RunOptions options;
  options.steps = 100000;
  options.check_every = 1;
  const RunResult r = run_simulation(scene, set, *solver, options);
  EXPECT_TRUE(r.unstable);
  EXPECT_FALSE(r.non_finite);
  EXPECT_LT(r.steps_done, 100000);
  EXPECT_GT(r.unstable_speed, r.unstable_wave_speed);
  EXPECT_GE(r.unstable_phyxel, 0);
  EXPECT_TRUE(r.outputs.empty());
}

}  // namespace
}  // namespace phyxel
