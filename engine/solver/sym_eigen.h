// Closed-form eigenvalues of a symmetric 3x3 matrix (the principal stresses of a Cauchy stress),
// templated on the scalar type: double on the CPU reference, float as on the GPU, whose twin is
// compute/shaders/sym_eigen.glsl (the same operations in the same order).
//
// The trigonometric solution of the characteristic cubic (Smith 1961) alone loses accuracy
// where two eigenvalues nearly coincide: the arccosine is taken of a value near +-1, and an
// eigenvalue of the close pair moves by about sqrt(eps) * |A| (3e-4 of |A| in float) where a
// symmetric matrix's eigenvalues are perfectly conditioned. So only the eigenvalue farthest from
// the other two is taken from the cubic (where its formula is insensitive to the arccosine), it
// is polished by one Newton step on the cubic (which also absorbs the loose trigonometric
// precision that Vulkan allows), and the other two come from the 2x2 matrix that A leaves on the
// plane orthogonal to that eigenvalue's eigenvector, by the cancellation-free 2x2 formula
// mean +- sqrt(half difference^2 + off-diagonal^2). Every eigenvalue is then within a few eps of
// |A| of the true one, repeated eigenvalues and the zero matrix included.
//
// Steps (S = A - tr(A)/3 I, scaled by its largest entry so that nothing overflows, underflows
// or divides by zero):
//   p = sqrt(tr(S^2) / 6) >= 1/sqrt(6),  r = det(S) / (2 p^3) clamped to [-1, 1],
//   phi = acos(r) / 3; the eigenvalues of S are 2 p cos(phi + 2 pi k / 3), k = 0, 1, 2.
//   r >= 0: the largest (k = 0) is at least sqrt(3) p from the others; r < 0: the smallest
//   (k = 2) is. Newton on det(l I - S) = l^3 - tr(S^2)/2 l - det(S), whose slope there is at
//   least 6 p^2 >= 1. Its eigenvector: the longest cross product of two rows of S - l I.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace phyxel {

// The eigenvalues of the symmetric matrix `a` in descending order. Only the upper triangle is
// read. Finite for every finite `a`; all equal to tr(a)/3 for a multiple of the identity (and
// zero for the zero matrix).
template <class Real>
Eigen::Matrix<Real, 3, 1> symmetric_eigenvalues(const Eigen::Matrix<Real, 3, 3>& a) {
  using V3 = Eigen::Matrix<Real, 3, 1>;
  using M3 = Eigen::Matrix<Real, 3, 3>;
  const Real q = (a(0, 0) + a(1, 1) + a(2, 2)) / Real(3);
  M3 s;
  s << a(0, 0) - q, a(0, 1), a(0, 2), a(0, 1), a(1, 1) - q, a(1, 2), a(0, 2), a(1, 2), a(2, 2) - q;
  const Real scale = s.cwiseAbs().maxCoeff();
  if (scale == Real(0)) return V3::Constant(q);
  s /= scale;
  const Real s2 = s.squaredNorm();  // tr(S^2) >= 1
  const Real p = std::sqrt(s2 / Real(6));
  const Real det = s.determinant();
  const Real r = std::clamp(det / (Real(2) * p * p * p), Real(-1), Real(1));
  const Real phi = std::acos(r) / Real(3);
  const bool top = r >= Real(0);  // the largest eigenvalue is the one apart
  Real l = Real(2) * p * std::cos(top ? phi : phi + Real(2.0943951023931957));  // + 2 pi / 3
  l -= (l * l * l - Real(0.5) * s2 * l - det) / (Real(3) * l * l - Real(0.5) * s2);
  // Its eigenvector, then an orthonormal basis (b, c) of the plane orthogonal to it.
  const M3 m = s - l * M3::Identity();
  const V3 c0 = m.row(1).cross(m.row(2)).transpose();
  const V3 c1 = m.row(2).cross(m.row(0)).transpose();
  const V3 c2 = m.row(0).cross(m.row(1)).transpose();
  const Real n0 = c0.squaredNorm(), n1 = c1.squaredNorm(), n2 = c2.squaredNorm();
  V3 v = n0 >= n1 && n0 >= n2 ? c0 : (n1 >= n2 ? c1 : c2);
  v.normalize();
  const V3 w = v.cwiseAbs();
  const V3 axis = w.x() <= w.y() && w.x() <= w.z() ? V3::UnitX()
                  : w.y() <= w.z()                 ? V3::UnitY()
                                                   : V3::UnitZ();
  const V3 b = v.cross(axis).normalized();
  const V3 c = v.cross(b);
  const V3 sb = s * b, sc = s * c;
  const Real t00 = b.dot(sb), t11 = c.dot(sc), t01 = Real(0.5) * (b.dot(sc) + c.dot(sb));
  const Real mid = Real(0.5) * (t00 + t11);
  const Real half = Real(0.5) * (t00 - t11);
  const Real rad = std::sqrt(half * half + t01 * t01);  // entries are O(1): no overflow
  V3 e = top ? V3(l, mid + rad, mid - rad) : V3(mid + rad, mid - rad, l);
  // The isolated eigenvalue is at least sqrt(3) p from the pair, so this only guards rounding.
  if (e.x() < e.y()) std::swap(e.x(), e.y());
  if (e.y() < e.z()) std::swap(e.y(), e.z());
  if (e.x() < e.y()) std::swap(e.x(), e.y());
  return V3::Constant(q) + scale * e;
}

}  // namespace phyxel
