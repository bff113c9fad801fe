// Tearing of overstressed tissue (issue #11, docs/tearing.md), shared by the CPU reference
// (solver/cpu_solver_tearing.cpp) and mirrored by the GPU solver
// (compute/shaders/solver_force_tear.comp).
//
// Material with `tear_stress` T (Pa) tears wherever it is overstressed, whatever loads it. At the
// end of every substep, after the stress pass of the substep's positions, a live neighbour pair
// (i, j) tears when the material between them is pulled apart harder than it holds:
//
//   s_ij = d^T sigma_ij d >= T_ij,   d = (x_j - x_i) / |x_j - x_i|   (current positions)
//   sigma_ij = (sigma_i + sigma_j) / 2,   T_ij = (T_i + T_j) / 2
//
// sigma the Cauchy stress of each phyxel (mls_model.h cauchy_stress, symmetrised), T its
// material's tear_stress; a pair with a side whose material has none never tears. s_ij is the
// normal stress across the plane between the two phyxels: under uniaxial tension sigma the pairs
// along the pull reach s = sigma and tear when sigma reaches T, pairs across it carry s = 0 and
// hold, so a crack opens across the load (mode I) instead of the phyxel crumbling, and it runs
// where the stress concentrates at its tip. The largest principal stress (the paper's criterion,
// eq 12 and section V) bounds s_ij from above: no pair tears where no phyxel's largest principal
// stress reaches T.
//
// A torn pair is severed exactly as a cut severs one (engine/solver/cutting.h: weight 0 on both
// sides for good, logged as (i, j, t = 0.5, torn), the precompute rerun for both phyxels), so
// cut faces, pieces, checkpoints and the renderer treat both alike. The forces of the substep in
// which a pair tears are those before it tore (it takes effect from the next stress pass).
//
// A phyxel left without a fit holds no pair: once cuts, tears or removals have left its live pairs
// too few or too flat to determine its gradient (its moment matrix regularised, mls_model.h), every
// pair it still has to a phyxel that tears also tears, at the next tear pass, whatever the
// stress. Such a phyxel carries little or no elastic energy of its own (docs/tearing.md,
// "Damaged phyxels"), and its stress says nothing of its pairs: a fragment left on one pair flew
// off to 5 cm (13 times the pair's rest length) while its inverted one-pair fit read -29 MPa, until
// the pair dominated the wall phyxel's fit and threw its neighbour out (docs/suction.md,
// "Resolution").
//
// Both sides of a pair decide alike: the pair is tested once, by its lower index, over the
// phyxels of the stress pass (the others have no current stress). In float (GPU) and double
// (CPU) decisions can differ only for pairs with s_ij within kTearParityTolerance (relative) of
// T_ij.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace phyxel {

// The relative band around the threshold within which float and double may decide a pair
// differently (the stress of one phyxel in float agrees with double to ~1e-5 relative).
inline constexpr double kTearParityTolerance = 1e-3;

// The pair's threshold: the mean of the two strengths, or 0 (never tears) when a side has none
// (a strength <= 0 or not finite means none).
template <class Real>
Real pair_tear_threshold(Real t_i, Real t_j) {
  const bool holds_i = t_i > Real(0) && std::isfinite(t_i);
  const bool holds_j = t_j > Real(0) && std::isfinite(t_j);
  return holds_i && holds_j ? Real(0.5) * (t_i + t_j) : Real(0);
}

// s_ij of the pair: the normal stress of the mean tensor across the plane between the phyxels.
// Zero for coincident phyxels (no direction).
template <class Real>
Real pair_normal_stress(const Eigen::Matrix<Real, 3, 3>& sigma_i,
                        const Eigen::Matrix<Real, 3, 3>& sigma_j,
                        const Eigen::Matrix<Real, 3, 1>& x_i,
                        const Eigen::Matrix<Real, 3, 1>& x_j) {
  const Eigen::Matrix<Real, 3, 1> r = x_j - x_i;
  const Real len2 = r.squaredNorm();
  if (!(len2 > Real(0))) return Real(0);
  const Eigen::Matrix<Real, 3, 3> mean = Real(0.5) * (sigma_i + sigma_j);
  return r.dot(mean * r) / len2;
}

// Whether a phyxel is left without a fit (see the top): its moment matrix regularised after it lost
// a pair (cut, torn or removed); fixed phyxels never are.
inline bool left_without_fit(bool regularised, bool lost_a_pair, bool fixed) {
  return regularised && lost_a_pair && !fixed;
}

// Whether the pair tears: a threshold (> 0) and s_ij at or above it.
template <class Real>
bool pair_tears(Real normal_stress, Real threshold) {
  return threshold > Real(0) && normal_stress >= threshold;
}

}  // namespace phyxel
