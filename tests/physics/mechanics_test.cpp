// Mechanics of the CPU reference solver: uniaxial stretch recovers E and nu, free vibration
// conserves energy, and the stable-step rule is below the measured stability limit.
#include <gtest/gtest.h>

#include <random>

#include "engine/cpu_solver.h"
#include "engine/simulation.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

// Relaxes a damped solver towards static equilibrium: steps until the kinetic energy has
// fallen below `tol` times its peak (at least `min_steps`, at most `max_steps`).
template <class S>
void relax(S& solver, double dt, int min_steps, int max_steps, double tol = 1e-12) {
  double peak = 0;
  for (int k = 0; k < max_steps; ++k) {
    solver.step(dt);
    if (k % 50 == 0) {
      const double ke = solver.energies().kinetic;
      peak = std::max(peak, ke);
      if (k >= min_steps && ke < tol * peak) return;
    }
  }
}

TEST(UniaxialStretch, RecoversYoungsModulusAndPoissonRatio) {
  // A free bar pulled by equal and opposite end loads: uniform uniaxial stress F/A away
  // from the ends (no clamp to disturb the lateral contraction).
  const double young = 1e5, poisson = 0.3, length = 0.1, side = 0.02, s = 0.0025;
  const double force = 0.04;  // 100 Pa on 4 cm^2: 0.1 % strain
  Scene scene = test::box_scene(Vec3(0, -side / 2, -side / 2), Vec3(length, side / 2, side / 2), s,
                                test::tissue(young, poisson, 0));
  Load pull;
  pull.region = test::box_shape(Vec3(length - s / 2, -1, -1), Vec3(1, 1, 1));
  pull.force = Vec3(force, 0, 0);
  Load hold = pull;
  hold.region = test::box_shape(Vec3(-1, -1, -1), Vec3(s / 2, 1, 1));
  hold.force = -pull.force;
  scene.objects[0].loads = {pull, hold};
  // Damping near critical for the first axial mode (c / 2L = 50 Hz).
  scene.objects[0].material.damping = 2 * 2 * 3.14159 * 50;
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, Vec3::Zero());
  const double dt = plan_time_step(scene, set).dt_stable;
  relax(solver, dt, 2000, 40000);

  auto displacement_at = [&](const Vec3& p) {
    for (size_t i = 0; i < set.size(); ++i)
      if ((set.rest[i] - p).norm() < 1e-9) return Vec3(solver.displacement()[i]);
    ADD_FAILURE() << "no phyxel at " << p.transpose();
    return Vec3(Vec3::Zero());
  };
  const double x1 = 0.03, x2 = 0.07;
  const double axial =
      (displacement_at(Vec3(x2, 0, 0)) - displacement_at(Vec3(x1, 0, 0)))[0] / (x2 - x1);
  const double lateral =
      (displacement_at(Vec3(0.05, side / 2, 0)) - displacement_at(Vec3(0.05, -side / 2, 0)))[1] /
      side;
  const double measured_young = force / (side * side) / axial;
  const double measured_poisson = -lateral / axial;
  EXPECT_NEAR(measured_young / young, 1.0, 0.02) << "E measured " << measured_young;
  EXPECT_NEAR(measured_poisson / poisson, 1.0, 0.02) << "nu measured " << measured_poisson;
}

TEST(FreeVibration, UndampedMotionConservesTotalEnergy) {
  // A cube set twisting and breathing, no gravity, no damping, 10^4 steps at half the
  // stable step: the total energy stays within 1 % of its initial value.
  Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.02), 0.0025, test::tissue());
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, Vec3::Zero());
  const Vec3 c(0.01, 0.01, 0.01);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 r = set.rest[i] - c;
    solver.velocity()[i] = 20 * Vec3(0, 0, 1).cross(r) + 30 * Vec3(r.x(), -r.y(), 0.5 * r.z());
  }
  const double dt = 0.5 * plan_time_step(scene, set).dt_stable;
  const double e0 = solver.energies().total();
  double worst = 0, min_strain = 1e300, max_strain = 0;
  for (int k = 1; k <= 10000; ++k) {
    solver.step(dt);
    if (k % 100 == 0) {
      const Energies e = solver.energies();
      worst = std::max(worst, std::abs(e.total() - e0) / e0);
      min_strain = std::min(min_strain, e.strain);
      max_strain = std::max(max_strain, e.strain);
    }
  }
  EXPECT_LT(worst, 0.01);
  // It really vibrated: energy moved between kinetic and strain.
  EXPECT_GT(max_strain, 0.3 * e0);
  EXPECT_LT(min_strain, 0.3 * e0);
}

// Largest eigenvalue of M^-1 K at rest by power iteration on the linearised forces.
double max_angular_frequency(const PhyxelSet& set) {
  CpuSolver<double> solver(set, Vec3::Zero());
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<Vec3> x(set.size());
  for (auto& v : x) v = Vec3(d(rng), d(rng), d(rng));
  double lambda = 0;
  const double eps = 1e-9;
  for (int it = 0; it < 300; ++it) {
    double norm = 0;
    for (const auto& v : x) norm += v.squaredNorm();
    norm = std::sqrt(norm);
    for (size_t i = 0; i < set.size(); ++i) solver.displacement()[i] = eps * x[i] / norm;
    solver.compute_forces();
    double dot = 0, next_norm = 0;
    for (size_t i = 0; i < set.size(); ++i) {
      const Vec3 kx = -solver.force()[i] / eps / set.mass[i];  // M^-1 K x / |x|
      dot += kx.dot(x[i]) / norm;
      x[i] = kx;
      next_norm += kx.squaredNorm();
    }
    lambda = dot;
  }
  return std::sqrt(std::max(lambda, 0.0));
}

TEST(StableStep, CourantRuleStaysBelowTheMeasuredLimit) {
  // Leapfrog is stable for dt < 2 / omega_max. The rule dt = 0.5 s / c_p must keep a margin
  // for every Poisson ratio and support radius we allow.
  for (double poisson : {0.0, 0.3, 0.45, 0.49}) {
    for (double h_factor : {1.5, 2.0, 3.0}) {
      Scene scene = test::box_scene(Vec3(0, 0, 0), Vec3(0.015, 0.015, 0.015), 0.0025,
                                    test::tissue(1e6, poisson), h_factor);
      const PhyxelSet set = sample_scene(scene);
      const double rule = plan_time_step(scene, set).dt_stable;
      const double limit = 2 / max_angular_frequency(set);
      EXPECT_LT(rule, 0.9 * limit)
          << "nu " << poisson << " h " << h_factor << " s: rule " << rule << " limit " << limit;
    }
  }
}

}  // namespace
}  // namespace phyxel
