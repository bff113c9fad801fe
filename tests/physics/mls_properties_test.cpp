// Property tests of the CPU reference MLS model (DESIGN.md section 6): patch test, rigid
// motions, balance of internal forces, force = -grad energy by finite differences.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <functional>
#include <random>

#include "engine/solver/cpu_solver.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

using DoubleSolver = CpuSolver<double>;

// A box with surface, edge and corner phyxels, so the one-sided stencils are covered too.
PhyxelSet small_box(double h_factor = 2.0, double poisson = 0.3) {
  return sample_scene(test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.015, 0.0125), 0.0025,
                                      test::tissue(1e6, poisson), h_factor));
}

void set_field(DoubleSolver& s, const PhyxelSet& set, const Eigen::Matrix3d& g, const Vec3& t) {
  for (size_t i = 0; i < set.size(); ++i) s.displacement()[i] = g * set.rest[i] + t;
}

double max_force(const DoubleSolver& s) {
  double m = 0;
  for (const auto& f : s.force()) m = std::max(m, f.norm());
  return m;
}

TEST(MlsPatch, LinearDisplacementFieldIsReproducedExactly) {
  for (double hf : {2.0, 2.5, 3.0}) {
    const PhyxelSet set = small_box(hf);
    DoubleSolver solver(set, Vec3::Zero());
    ASSERT_EQ(solver.regularised_count(), 0u);
    std::mt19937 rng(7);
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::Matrix3d g = test::random_matrix(rng, 0.3);
      set_field(solver, set, g, Vec3(0.01, -0.02, 0.03));
      for (size_t i = 0; i < set.size(); ++i) {
        ASSERT_LT((solver.gradient(i) - g).cwiseAbs().maxCoeff(), 1e-10)
            << "phyxel " << i << " h = " << hf << " s";
      }
    }
  }
}

TEST(MlsPatch, UniformStrainGivesNoInternalForceInside) {
  // A homogeneous deformation is an equilibrium state away from the boundary.
  const PhyxelSet set = small_box();
  DoubleSolver solver(set, Vec3::Zero());
  Eigen::Matrix3d g;
  g << 0.05, 0.01, 0, 0.01, -0.02, 0.003, 0, 0.003, 0.01;
  set_field(solver, set, g, Vec3::Zero());
  solver.compute_forces();
  const double scale = max_force(solver);
  ASSERT_GT(scale, 0);
  const NeighbourLists& nbr = solver.neighbours();
  // Phyxels two or more layers inside, whose neighbours all have complete stencils.
  for (size_t i = 0; i < set.size(); ++i) {
    bool deep = nbr.count(i) == 26;
    for (uint32_t k = nbr.offset[i]; deep && k < nbr.offset[i + 1]; ++k)
      deep = nbr.count(nbr.index[k]) == 26;
    if (deep) {
      EXPECT_LT(solver.force()[i].norm(), 1e-9 * scale) << "phyxel " << i;
    }
  }
}

TEST(RigidMotion, TranslationAndLargeRotationsGiveZeroStrainAndForce) {
  const PhyxelSet set = small_box();
  DoubleSolver solver(set, Vec3::Zero());
  // Force scale: a 1 % stretch.
  set_field(solver, set, Eigen::Vector3d(0.01, 0, 0).asDiagonal(), Vec3::Zero());
  solver.compute_forces();
  const double stretch_force = max_force(solver);
  const double stretch_energy = solver.internal_energy();
  for (double angle : {0.0, 0.3, 1.5707963, 2.5, 3.1}) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(angle, Vec3(1, 2, 3).normalized()).toRotationMatrix();
    set_field(solver, set, r - Eigen::Matrix3d::Identity(), Vec3(0.05, -0.1, 0.2));
    solver.compute_forces();
    EXPECT_LT(max_force(solver), 1e-9 * stretch_force) << "angle " << angle;
    EXPECT_LT(solver.internal_energy(), 1e-12 * stretch_energy) << "angle " << angle;
  }
}

TEST(ForceBalance, InternalForcesSumToZero) {
  const PhyxelSet set = small_box();
  DoubleSolver solver(set, Vec3::Zero());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> d(-0.002, 0.002);
  for (auto& u : solver.displacement()) u = Vec3(d(rng), d(rng), d(rng));
  solver.compute_forces();
  Vec3 sum = Vec3::Zero();
  for (const auto& f : solver.force()) sum += f;
  EXPECT_LT(sum.norm(), 1e-12 * max_force(solver) * double(set.size()));
}

// Central differences of the energy against the forces, relative 1e-6.
// `prepare` edits the solver first (severs pairs).
void expect_force_is_minus_energy_gradient(const PhyxelSet& set, double amplitude,
                                           const std::function<void(DoubleSolver&)>& prepare = {}) {
  DoubleSolver solver(set, Vec3::Zero());
  if (prepare) prepare(solver);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> d(-amplitude, amplitude);
  // A smooth large deformation (stretch, shear, rotation) plus per-phyxel noise.
  const Eigen::Matrix3d g = test::random_matrix(rng, 0.2) +
                            Eigen::AngleAxisd(0.7, Vec3(0, 1, 1).normalized()).toRotationMatrix() -
                            Eigen::Matrix3d::Identity();
  for (size_t i = 0; i < set.size(); ++i)
    solver.displacement()[i] = g * set.rest[i] + Vec3(d(rng), d(rng), d(rng));
  solver.compute_forces();
  const std::vector<Vec3> force = solver.force();
  double scale = 0;
  for (const auto& f : force) scale = std::max(scale, f.norm());
  const double eps = 1e-7;
  std::uniform_int_distribution<size_t> pick(0, set.size() - 1);
  for (int trial = 0; trial < 40; ++trial) {
    const size_t i = trial < 8 ? trial * (set.size() - 1) / 7 : pick(rng);
    for (int c = 0; c < 3; ++c) {
      const double keep = solver.displacement()[i][c];
      solver.displacement()[i][c] = keep + eps;
      const double up = solver.internal_energy();
      solver.displacement()[i][c] = keep - eps;
      const double down = solver.internal_energy();
      solver.displacement()[i][c] = keep;
      const double numeric = -(up - down) / (2 * eps);
      EXPECT_NEAR(force[i][c], numeric, 1e-6 * scale) << "phyxel " << i << " axis " << c;
    }
  }
}

TEST(EnergyConsistency, ForceIsMinusEnergyGradient) {
  expect_force_is_minus_energy_gradient(small_box(2.0, 0.3), 2e-4);
  expect_force_is_minus_energy_gradient(small_box(2.6, 0.45), 2e-4);
}

TEST(EnergyConsistency, HoldsWithRegularisedMomentMatrices) {
  // A plate thinner than the spacing has one layer of phyxels: every moment matrix is
  // singular (coplanar neighbours) and regularised. Sampling refuses such a plate for a run
  // (tests/sampling/small_body_test.cpp); the solver must still cope with one.
  const PhyxelSet set = sample_scene(
      test::box_scene(Vec3(0, 0, 0), Vec3(0.015, 0.0125, 0.001), 0.0025, test::tissue()),
      SamplingOptions{false});
  DoubleSolver solver(set, Vec3::Zero());
  ASSERT_EQ(solver.regularised_count(), set.size());
  expect_force_is_minus_energy_gradient(set, 2e-4);
}

// Severs every pair crossing the plane x = x_cut, and every pair of phyxel `lone` but its first:
// a crack through the box, and a phyxel left hanging by one pair (rank-one moment matrix).
void crack(DoubleSolver& solver, const PhyxelSet& set, double x_cut, uint32_t lone) {
  std::vector<SeveredPair> pairs;
  const NeighbourLists& nbr = solver.neighbours();
  for (uint32_t i = 0; i < set.size(); ++i)
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      if (j <= i) continue;
      const bool crosses = (set.rest[i].x() - x_cut) * (set.rest[j].x() - x_cut) < 0;
      const bool hangs = (i == lone || j == lone) && k != nbr.offset[i] &&
                         !(j == lone && nbr.index[nbr.offset[lone]] == i);
      if (crosses || hangs) pairs.push_back({i, j, 0.5f, true});
    }
  solver.sever_pairs(pairs);
}

TEST(DamageFactor, IsOneIntactZeroForAFragmentAndTheEigenvalueRatioBetween) {
  EXPECT_EQ(damage_factor(2.0, 2.0), 1.0);
  EXPECT_EQ(damage_factor(0.5, 2.0), 0.25);
  EXPECT_EQ(damage_factor(0.0, 2.0), 0.0);
  EXPECT_EQ(damage_factor(-1e-18, 2.0), 0.0);  // round-off of a singular matrix
  EXPECT_EQ(damage_factor(0.0, 0.0), 1.0);     // singular from the start (a one-layer plate)
}

TEST(EnergyConsistency, HoldsForDamagedPhyxels) {
  // Damage scales a phyxel's elastic volume and hourglass stiffness (docs/tearing.md): the
  // forces must stay minus the gradient of the scaled energy, across a crack and at a phyxel
  // hanging by one pair.
  const PhyxelSet set = small_box(2.0, 0.3);
  const uint32_t lone = static_cast<uint32_t>(set.size() / 2);
  expect_force_is_minus_energy_gradient(set, 2e-4, [&](DoubleSolver& solver) {
    crack(solver, set, 0.0101, lone);
    ASSERT_GT(solver.severed_count(), 50u);
  });
}

TEST(Damage, PhyxelsAwayFromACrackAreUnchanged) {
  const PhyxelSet set = small_box(2.0, 0.3);
  DoubleSolver intact(set, Vec3::Zero()), cracked(set, Vec3::Zero());
  const uint32_t lone = static_cast<uint32_t>(set.size() / 2);
  crack(cracked, set, 0.0101, lone);
  // Away from the crack nothing changed: the same uniform stretch, the same forces.
  const Eigen::Matrix3d g = 0.01 * Eigen::Matrix3d::Identity();
  set_field(intact, set, g, Vec3::Zero());
  set_field(cracked, set, g, Vec3::Zero());
  intact.compute_forces();
  cracked.compute_forces();
  // A phyxel's force reads its neighbours' stress: compare those with no damaged neighbour.
  std::vector<bool> damaged(set.size(), false);
  for (const SeveredPair& p : cracked.severed_log()) damaged[p.i] = damaged[p.j] = true;
  const NeighbourLists& nbr = intact.neighbours();
  size_t compared = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    bool near = damaged[i];
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k)
      near = near || damaged[nbr.index[k]];
    if (near) continue;
    EXPECT_TRUE(intact.force()[i] == cracked.force()[i]) << i;
    ++compared;
  }
  EXPECT_GT(compared, 20u);
}

TEST(Regularisation, SparseNeighbourhoodsStayFinite) {
  // Support radius just above sqrt(2) s: 18 neighbours inside, few at the corners.
  const PhyxelSet set = small_box(1.45);
  DoubleSolver solver(set, Vec3::Zero());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> d(-0.003, 0.003);
  for (auto& u : solver.displacement()) u = Vec3(d(rng), d(rng), d(rng));
  solver.compute_forces();
  for (const auto& f : solver.force()) ASSERT_TRUE(f.allFinite());
}

}  // namespace
}  // namespace phyxel
