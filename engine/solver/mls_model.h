// Pointwise pieces of the MLS elasticity model (DESIGN.md section 3), shared by the CPU solver
// and mirrored by the GPU shaders:
//  - the regularised inverse of the moment matrix A_i = sum_j w_ij x_ij x_ij^T,
//  - St Venant-Kirchhoff stress from the deformation gradient F = I + grad u, with the
//    volume-conservation term k_v/2 (det F - 1)^2 (Mueller et al. 2004),
//  - their energy density,
//  - the Cauchy stress and its von Mises and largest principal values (outputs, tearing).
// Convention: grad u has entries G_ab = d u_a / d x_b, Green strain E = (F^T F - I)/2,
// second Piola-Kirchhoff S = lambda' tr(E) I + 2 mu E, first Piola P = F S + k_v (J - 1) cof F,
// where lambda' = lambda - k_v so that the small-strain response is exactly (E, nu).
// With this convention dW/dF = P and there is no factor 2 (the paper's eq 14 has one because
// it writes the strain energy with a different strain convention).
#pragma once

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <algorithm>

#include "engine/solver/sym_eigen.h"

namespace phyxel {

// Largest condition number of A_i used as is. Beyond it (too few, coplanar or collinear
// neighbours, typically after a cut) the small eigenvalues are raised to lambda_max / kMaxCond,
// which bounds the gradient weights and so the forces. A lattice stencil stays far below this.
inline constexpr double kMaxMomentCondition = 100.0;

struct MomentInverse {
  Eigen::Matrix3d inverse = Eigen::Matrix3d::Zero();
  // A^-1 A A^-1 - A^-1: zero unless regularised; makes the hourglass force exact then too.
  Eigen::Matrix3d residual = Eigen::Matrix3d::Zero();
  double condition = 1;
  bool regularised = false;
};

inline MomentInverse regularised_inverse(const Eigen::Matrix3d& a) {
  MomentInverse out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(a);
  Eigen::Vector3d lam = eig.eigenvalues();  // ascending
  const double lmax = lam[2];
  if (!(lmax > 0)) {  // no neighbours: no gradient information at all
    out.condition = std::numeric_limits<double>::infinity();
    out.regularised = true;
    return out;
  }
  out.condition = lam[0] > 0 ? lmax / lam[0] : std::numeric_limits<double>::infinity();
  const double floor = lmax / kMaxMomentCondition;
  if (out.condition > kMaxMomentCondition) {
    out.regularised = true;
    for (int k = 0; k < 3; ++k) lam[k] = std::max(lam[k], floor);
  }
  const Eigen::Matrix3d& q = eig.eigenvectors();
  out.inverse = q * lam.cwiseInverse().asDiagonal() * q.transpose();
  if (out.regularised) out.residual = out.inverse * a * out.inverse - out.inverse;
  return out;
}

// The smallest eigenvalue of a moment matrix.
inline double min_moment_eigenvalue(const Eigen::Matrix3d& a) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(a, Eigen::EigenvaluesOnly).eigenvalues()[0];
}

// A phyxel's damage factor in [0, 1] (docs/tearing.md, "Damaged phyxels"): lambda_min of its
// moment matrix over the pairs still alive, over lambda_min with every pair to a phyxel not
// removed (cut and torn pairs included); 1 while nothing was cut or torn.
inline double damage_factor(double lmin, double reference_lmin) {
  if (!(reference_lmin > 0)) return lmin >= reference_lmin ? 1.0 : 0.0;
  return std::clamp(lmin / reference_lmin, 0.0, 1.0);
}

// Cofactor matrix of F (= det F * F^-T where F is invertible), defined for every F.
template <class Real>
Eigen::Matrix<Real, 3, 3> cofactor(const Eigen::Matrix<Real, 3, 3>& f) {
  Eigen::Matrix<Real, 3, 3> c;
  c.col(0) = f.col(1).cross(f.col(2));
  c.col(1) = f.col(2).cross(f.col(0));
  c.col(2) = f.col(0).cross(f.col(1));
  return c;
}

template <class Real>
struct ElasticParams {
  Real lambda_svk;  // Lame lambda minus k_v
  Real mu;
  Real kv;
};

// First Piola-Kirchhoff stress P = dW/dF; also returns W (energy per unit rest volume).
template <class Real>
Eigen::Matrix<Real, 3, 3> first_piola(const Eigen::Matrix<Real, 3, 3>& f,
                                      const ElasticParams<Real>& m, Real* energy_density) {
  using M3 = Eigen::Matrix<Real, 3, 3>;
  const M3 e = Real(0.5) * (f.transpose() * f - M3::Identity());
  const Real tr = e.trace();
  const M3 s = m.lambda_svk * tr * M3::Identity() + Real(2) * m.mu * e;
  const M3 cof = cofactor(f);
  const Real j = f.col(0).dot(cof.col(0));
  if (energy_density)
    *energy_density = m.mu * e.squaredNorm() + Real(0.5) * m.lambda_svk * tr * tr +
                      Real(0.5) * m.kv * (j - 1) * (j - 1);
  return f * s + m.kv * (j - 1) * cof;
}

// Cauchy stress sigma = P F^T / det F of a deformed phyxel (P itself where |det F| <= 1e-12).
// Symmetric in exact arithmetic: P F^T = F S F^T + k_v (J - 1) J I.
template <class Real>
Eigen::Matrix<Real, 3, 3> cauchy_stress(const Eigen::Matrix<Real, 3, 3>& f,
                                        const Eigen::Matrix<Real, 3, 3>& p) {
  using M3 = Eigen::Matrix<Real, 3, 3>;
  const Real j = f.determinant();
  return std::abs(j) > Real(1e-12) ? M3(p * f.transpose() / j) : M3(p);
}

// The von Mises equivalent of the Cauchy stress (for outputs).
template <class Real>
Real von_mises(const Eigen::Matrix<Real, 3, 3>& f, const Eigen::Matrix<Real, 3, 3>& p) {
  using M3 = Eigen::Matrix<Real, 3, 3>;
  const M3 sigma = cauchy_stress(f, p);
  const M3 dev = sigma - sigma.trace() / Real(3) * M3::Identity();
  return std::sqrt(Real(1.5) * dev.squaredNorm());
}

// The largest principal value of the Cauchy stress (the tearing criterion, paper eq 12 and
// section V): the largest eigenvalue of sigma, symmetrised against rounding.
template <class Real>
Real max_principal_stress(const Eigen::Matrix<Real, 3, 3>& f, const Eigen::Matrix<Real, 3, 3>& p) {
  using M3 = Eigen::Matrix<Real, 3, 3>;
  const M3 sigma = cauchy_stress(f, p);
  return symmetric_eigenvalues<Real>(Real(0.5) * (sigma + sigma.transpose())).x();
}

}  // namespace phyxel
