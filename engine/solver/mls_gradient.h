// F = I + grad u of one phyxel from the displacement of its rest neighbours, as the renderer's
// deform pass (render/shaders/deform_surfels.comp) computes it and in double: the poly6 weights
// of the rest distances within the object's support radius h (lengths in units of h, the
// kernel's constant dropped: it cancels in M A^-1), the pairs `joined(e, j)` accepts (pair e of
// the CSR row, neighbour j: the live ones), and the solver's regularised inverse of A
// (mls_model.h), so that F is the solver's gradient wherever the pair weights are the kernel's.
// What aspiration maps its new surfaces back to rest space with (engine/surgery/aspiration.h),
// and the deform pass's CPU twin in tests.
#pragma once

#include <Eigen/LU>
#include <cmath>
#include <cstdint>
#include <vector>

#include "engine/solver/mls_model.h"
#include "engine/solver/neighbours.h"

namespace phyxel {

struct PointDeformation {
  Eigen::Matrix3d f = Eigen::Matrix3d::Identity();
  // false where no live neighbour is within h or F is singular (|det F| <= 1e-6): f is then I
  // and the deform pass keeps the rest normal.
  bool usable = false;
};

template <class Joined>
PointDeformation mls_deformation(const std::vector<Vec3>& rest, const NeighbourLists& nbr,
                                 const std::vector<Vec3>& u, uint32_t i, double h,
                                 Joined&& joined) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero(), m = Eigen::Matrix3d::Zero();
  for (uint32_t e = nbr.offset[i]; e < nbr.offset[i + 1]; ++e) {
    const uint32_t j = nbr.index[e];
    if (!joined(e, j)) continue;
    const Vec3 x = (rest[j] - rest[i]) / h;
    const double q = 1 - x.squaredNorm();
    if (q <= 0) continue;
    const double w = q * q * q;
    a += w * x * x.transpose();
    m += w * ((u[j] - u[i]) / h) * x.transpose();
  }
  PointDeformation out;
  if (!(a.trace() > 0)) return out;
  const Eigen::Matrix3d f = Eigen::Matrix3d::Identity() + m * regularised_inverse(a).inverse;
  if (!(std::abs(f.determinant()) > 1e-6)) return out;
  out.f = f;
  out.usable = true;
  return out;
}

}  // namespace phyxel
