// Mechanics of the CPU reference solver: free vibration conserves energy, and the stable-step
// rule is below the measured stability limit. (Uniaxial stretch and the cantilever against
// CalculiX are in tests/validation.)
#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

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

// Largest eigenvalue of M^-1 K at rest by power iteration on the linearised forces, after
// severing the pairs (i < j) for which `cut` says so.
double max_angular_frequency(const PhyxelSet& set,
                             const std::function<bool(const Vec3&, const Vec3&)>& cut = {}) {
  CpuSolver<double> solver(set, Vec3::Zero());
  if (cut) {
    std::vector<SeveredPair> pairs;
    const NeighbourLists& nbr = solver.neighbours();
    for (uint32_t i = 0; i < set.size(); ++i)
      for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k)
        if (nbr.index[k] > i && cut(set.rest[i], set.rest[nbr.index[k]]))
          pairs.push_back({i, nbr.index[k], 0.5f});
    solver.sever_pairs(pairs);
  }
  return test::max_angular_frequency(solver, set);
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

TEST(StableStep, CutsKeepTheMarginOfTheCourantRule) {
  // Cut faces, like sampled surfaces, must stay within the measured limit, as must a one-layer
  // sliver between two cuts and the corner where two cuts cross.
  Scene scene =
      test::box_scene(Vec3(0, 0, 0), Vec3(0.015, 0.015, 0.015), 0.0025, test::tissue(1e6, 0.3));
  const PhyxelSet set = sample_scene(scene);
  const double rule = plan_time_step(scene, set).dt_stable;
  auto across = [](double plane, int axis) {
    return [=](const Vec3& a, const Vec3& b) { return (a[axis] - plane) * (b[axis] - plane) < 0; };
  };
  const auto plane = across(0.00625, 0);
  const auto sliver = [&](const Vec3& a, const Vec3& b) {
    return plane(a, b) || across(0.00875, 0)(a, b);
  };
  const auto crossing = [&](const Vec3& a, const Vec3& b) {
    return plane(a, b) || across(0.00625, 1)(a, b);
  };
  const double intact = 2 / max_angular_frequency(set);
  for (const auto& [name, cut] :
       {std::pair<const char*, std::function<bool(const Vec3&, const Vec3&)>>{"plane", plane},
        {"sliver", sliver},
        {"crossing", crossing}}) {
    const double limit = 2 / max_angular_frequency(set, cut);
    EXPECT_LT(rule, 0.9 * limit) << name << ": rule " << rule << " limit " << limit;
    EXPECT_GT(limit, 0.9 * intact) << name << ": limit " << limit << " intact " << intact;
  }
}

}  // namespace
}  // namespace phyxel
