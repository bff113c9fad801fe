// The poly6 smoothing kernel of the paper's eq 8 (Mueller et al. 2004):
//   w(r, h) = 315 / (64 pi h^9) (h^2 - r^2)^3   for r < h, else 0.
// Normalised: its integral over R^3 is 1.
#pragma once

#include <numbers>

namespace phyxel {

template <class Real>
Real poly6(Real r2, Real h) {
  const Real h2 = h * h;
  if (r2 >= h2) return Real(0);
  const Real d = h2 - r2;
  const Real h3 = h2 * h;
  return Real(315.0 / (64.0 * std::numbers::pi)) / (h3 * h3 * h3) * d * d * d;
}

}  // namespace phyxel
