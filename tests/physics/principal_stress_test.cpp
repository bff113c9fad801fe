// The largest principal stress (tearing): the closed-form symmetric 3x3 eigenvalues
// (engine/solver/sym_eigen.h, in double and in float as on the GPU) against Eigen's iterative
// solver on many random tensors, repeated, zero and nearly repeated eigenvalues included; the
// CPU solver's per-phyxel value for a rigid motion, a homogeneous stretch and a bar pulled by
// end loads, against closed forms.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "engine/solver/solver.h"
#include "engine/solver/sym_eigen.h"
#include "tests/physics/physics_fixtures.h"

namespace phyxel {
namespace {

// A random symmetric tensor Q diag(l) Q^T with a random rotation Q and eigenvalues of one of
// several kinds: distinct, a pair repeated (the larger or the smaller), all three equal,
// a pair nearly repeated (relative gaps 1e-3 down to 1e-15), zero, rank one, or random
// entries; magnitudes from 1e-20 to 1e20.
Eigen::Matrix3d random_tensor(std::mt19937& rng, int kind) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_int_distribution<int> exponent(-20, 20);
  const double scale = std::pow(10.0, exponent(rng));
  const double a = u(rng), b = u(rng), c = u(rng);
  const double gap = std::pow(10.0, -3 - 3 * (kind % 5));  // 1e-3 ... 1e-15
  Eigen::Vector3d l;
  switch (kind % 8) {
    case 0:
      l = {a, b, c};
      break;
    case 1:
      l = {a, a, b};
      break;  // a pair repeated
    case 2:
      l = {a, a, a};
      break;  // a multiple of the identity
    case 3:
      l = {a, a * (1 + gap), b};
      break;  // a pair nearly repeated
    case 4:
      l = {a, a + gap * std::abs(b), 0};
      break;
    case 5:
      l = {0, 0, 0};
      break;
    case 6:
      l = {a, 0, 0};
      break;  // rank one (uniaxial stress)
    default: {
      Eigen::Matrix3d m;
      for (int k = 0; k < 9; ++k) m.data()[k] = u(rng);
      return scale * (m + m.transpose());
    }
  }
  const Eigen::Quaterniond q(Eigen::Vector4d(u(rng), u(rng), u(rng), u(rng)).normalized());
  const Eigen::Matrix3d r = q.toRotationMatrix();
  return scale * (r * l.asDiagonal() * r.transpose());
}

// Largest deviation from Eigen's iterative solver (in double, on the same matrix) relative to
// the matrix's largest eigenvalue magnitude, over `count` tensors; checks order and finiteness.
template <class Real>
double worst_relative_error(int count, unsigned seed) {
  std::mt19937 rng(seed);
  double worst = 0;
  for (int k = 0; k < count; ++k) {
    const Eigen::Matrix<Real, 3, 3> a = random_tensor(rng, k).cast<Real>();
    const Eigen::Matrix3d exact = a.template cast<double>();  // the matrix actually solved
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> reference(exact, Eigen::EigenvaluesOnly);
    const Eigen::Vector3d want = reference.eigenvalues().reverse();  // descending
    const Eigen::Vector3d got = symmetric_eigenvalues<Real>(a).template cast<double>();
    EXPECT_TRUE(got.allFinite()) << "tensor " << k << "\n" << exact;
    EXPECT_GE(got[0], got[1]) << "tensor " << k;
    EXPECT_GE(got[1], got[2]) << "tensor " << k;
    const double norm = want.cwiseAbs().maxCoeff();
    const double error = (got - want).cwiseAbs().maxCoeff();
    if (norm == 0) {
      EXPECT_EQ(error, 0) << "tensor " << k;
      continue;
    }
    EXPECT_LE(error, 32 * std::numeric_limits<Real>::epsilon() * norm)
        << "tensor " << k << " kind " << k % 8 << "\n"
        << exact << "\nwant " << want.transpose() << "\ngot  " << got.transpose();
    worst = std::max(worst, error / norm);
  }
  return worst;
}

std::string format(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", x);
  return text;
}

TEST(SymmetricEigenvalues, DoubleMatchesEigenOnRandomTensors) {
  RecordProperty("worst_relative_error", format(worst_relative_error<double>(40000, 11)));
}

TEST(SymmetricEigenvalues, FloatMatchesEigenOnRandomTensors) {
  // The GPU's formula (compute/shaders/sym_eigen.glsl) in float: within 64 float eps of the
  // largest eigenvalue even for pairs nearly repeated, where the plain trigonometric formula
  // is off by about sqrt(eps) (3e-4). Measured: 3.6e-7 (3 eps); in double 1.6e-15 (7 eps).
  RecordProperty("worst_relative_error", format(worst_relative_error<float>(40000, 12)));
}

TEST(SymmetricEigenvalues, ExactCases) {
  using V3 = Eigen::Vector3d;
  EXPECT_EQ(symmetric_eigenvalues<double>(Eigen::Matrix3d::Zero()), V3::Zero());
  EXPECT_EQ(symmetric_eigenvalues<float>(Eigen::Matrix3f::Zero()), Eigen::Vector3f::Zero());
  EXPECT_EQ(symmetric_eigenvalues<double>(-2.5 * Eigen::Matrix3d::Identity()), V3::Constant(-2.5));
  // Uniaxial stress along a diagonal direction: one eigenvalue 7, two 0.
  const V3 n = V3(1, 2, -2) / 3;
  const V3 e = symmetric_eigenvalues<double>(7 * n * n.transpose());
  EXPECT_NEAR(e[0], 7, 1e-14);
  EXPECT_NEAR(e[1], 0, 1e-14);
  EXPECT_NEAR(e[2], 0, 1e-14);
  // Only the upper triangle is read.
  Eigen::Matrix3d upper;
  upper << 1, 2, 3, 0, 4, 5, 0, 0, 6;
  Eigen::Matrix3d full = upper;
  full.triangularView<Eigen::StrictlyLower>() = upper.transpose();
  EXPECT_LE((symmetric_eigenvalues<double>(upper) - symmetric_eigenvalues<double>(full))
                .cwiseAbs()
                .maxCoeff(),
            1e-14);
  // Subnormal and huge entries neither underflow to NaN nor overflow.
  for (const double s : {1e-310, 1e-300, 1e300}) {
    const V3 big = symmetric_eigenvalues<double>(s * n * n.transpose());
    EXPECT_TRUE(big.allFinite()) << s;
    EXPECT_NEAR(big[0] / s, 1, 1e-12) << s;
  }
}

using Cpu = CpuSolver<double>;

PhyxelSet block(const Material& m = test::tissue(1e5, 0.3)) {
  return sample_scene(test::box_scene(Vec3(0, 0, 0), Vec3(0.02, 0.015, 0.0125), 0.0025, m, 2.0));
}

TEST(MaxPrincipalStress, OffByDefaultAndZeroForARigidMotion) {
  const PhyxelSet set = block();
  Cpu solver(set, Vec3::Zero());
  EXPECT_FALSE(solver.principal_stress());
  EXPECT_TRUE(solver.max_principal_stress().empty());
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  for (size_t i = 0; i < set.size(); ++i)
    solver.displacement()[i] = (r - Eigen::Matrix3d::Identity()) * set.rest[i] + Vec3(1, 2, 3);
  solver.set_principal_stress(true);  // computes it at once
  ASSERT_EQ(solver.max_principal_stress().size(), set.size());
  for (size_t i = 0; i < set.size(); ++i)
    EXPECT_NEAR(solver.max_principal_stress()[i], 0, 1e-6) << i;  // 1e5 Pa x 1e-11
  solver.set_principal_stress(false);
  EXPECT_TRUE(solver.max_principal_stress().empty());
}

TEST(MaxPrincipalStress, HomogeneousStretchGivesTheClosedFormAtEveryPhyxel) {
  // u = (F - I) x with F = diag(1.02, 0.995, 0.99): the MLS gradient is exact at every phyxel
  // (patch test), so every phyxel's sigma = (F S F^T + k_v (J - 1) J I) / J, with Green strain
  // E = (F^2 - I) / 2 and S = lambda' tr(E) I + 2 mu E, largest along x.
  const Material m = test::tissue(1e5, 0.3);
  const PhyxelSet set = block(m);
  Cpu solver(set, Vec3::Zero());
  const Vec3 stretch(1.02, 0.995, 0.99);
  for (size_t i = 0; i < set.size(); ++i)
    solver.displacement()[i] = (stretch - Vec3::Ones()).cwiseProduct(set.rest[i]);
  solver.set_principal_stress(true);
  const double kv = volume_stiffness(m), lambda = lame_lambda(m) - kv, mu = lame_mu(m);
  const Vec3 green = 0.5 * (stretch.cwiseProduct(stretch) - Vec3::Ones());
  const double j = stretch.prod();
  const double sxx =
      (stretch.x() * stretch.x() * (lambda * green.sum() + 2 * mu * green.x()) + kv * (j - 1) * j) /
      j;
  ASSERT_GT(sxx, 1000);  // 2 % stretch of a 100 kPa material
  for (size_t i = 0; i < set.size(); ++i)
    EXPECT_NEAR(solver.max_principal_stress()[i], sxx, 1e-8 * sxx) << "phyxel " << i;
}

TEST(MaxPrincipalStress, BarPulledByEndLoadsCarriesTheForceOverItsSection) {
  // A 4 x 1 x 1 cm bar pulled by equal and opposite end loads, damped to rest: away from the
  // loaded ends the stress is uniaxial, sigma_xx = F / A (Cauchy, on the section narrowed by
  // the lateral contraction: nu F / (E A) = 0.03 % here), the other principal values 0. The
  // largest principal stress of the phyxels of its middle half is that within 1 % (0.2 % measured).
  Scene scene = test::box_scene(Vec3(0, -0.005, -0.005), Vec3(0.04, 0.005, 0.005), 0.0025,
                                test::tissue(1e5, 0.3, 600), 2.0);
  const double force = 0.01, area = 1e-4;  // 100 Pa
  Load pull, push;
  pull.region = test::box_shape(Vec3(0.0399, -1, -1), Vec3(1, 1, 1));
  pull.force = Vec3(force, 0, 0);
  push.region = test::box_shape(Vec3(-1, -1, -1), Vec3(0.0001, 1, 1));
  push.force = Vec3(-force, 0, 0);
  scene.objects[0].loads = {pull, push};
  scene.objects[0].material.tear_stress = 1e3;  // tearing is possible: the run computes it
  ASSERT_TRUE(scene.tearing_possible());
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  scene.simulation.dt = plan_time_step(scene, set).dt_stable;
  scene.simulation.steps = 1000;
  RunOptions options;
  options.steps = scene.simulation.steps;
  run_simulation(scene, set, *solver, options);
  const PointState state = solver->read_state(true);
  ASSERT_EQ(state.max_principal_stress.size(), set.size());
  const double expected = force / area;
  int middle = 0;
  double worst = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    if (std::abs(set.rest[i].x() - 0.02) > 0.01) continue;
    ++middle;
    EXPECT_NEAR(state.max_principal_stress[i], expected, 0.01 * expected)
        << "phyxel " << i << " at " << set.rest[i].transpose();
    worst = std::max(worst, std::abs(state.max_principal_stress[i] / expected - 1));
  }
  EXPECT_EQ(middle, 9 * 5 * 5);
  RecordProperty("worst_relative_error", format(worst));
}

}  // namespace
}  // namespace phyxel
