// Closed-form eigenvalues of a symmetric 3x3 matrix: the GLSL twin of
// engine/solver/sym_eigen.h (the same operations in the same order; see there why the
// eigenvalue apart from the other two comes from the cubic, polished by a Newton step, and the
// other two from the 2x2 matrix on the plane orthogonal to its eigenvector). Include after
// layout.h.
#ifndef PHYXEL_SYM_EIGEN_GLSL
#define PHYXEL_SYM_EIGEN_GLSL

// The eigenvalues of the symmetric `a` in descending order; only the upper triangle is read
// (a[col][row] with row <= col). Finite for every finite `a`.
vec3 sym_eigenvalues(mat3 a) {
  const float q = (a[0][0] + a[1][1] + a[2][2]) / 3.0;
  mat3 s = mat3(a[0][0] - q, a[1][0], a[2][0],  //
                a[1][0], a[1][1] - q, a[2][1],  //
                a[2][0], a[2][1], a[2][2] - q);
  const float scale = max(max(max(abs(s[0][0]), abs(s[1][1])), max(abs(s[2][2]), abs(s[1][0]))),
                          max(abs(s[2][0]), abs(s[2][1])));
  if (scale == 0.0) return vec3(q);
  s *= 1.0 / scale;
  const float s2 = dot(s[0], s[0]) + dot(s[1], s[1]) + dot(s[2], s[2]);  // tr(S^2) >= 1
  const float p = sqrt(s2 / 6.0);
  const float det = determinant(s);
  const float r = clamp(det / (2.0 * p * p * p), -1.0, 1.0);
  const float phi = acos(r) / 3.0;
  const bool top = r >= 0.0;  // the largest eigenvalue is the one apart
  float l = 2.0 * p * cos(top ? phi : phi + 2.0943951023931957);
  l -= (l * l * l - 0.5 * s2 * l - det) / (3.0 * l * l - 0.5 * s2);
  // Its eigenvector (S is symmetric: rows are columns), then a basis (b, c) of the plane
  // orthogonal to it.
  const mat3 m = s - l * mat3(1.0);
  const vec3 c0 = cross(m[1], m[2]);
  const vec3 c1 = cross(m[2], m[0]);
  const vec3 c2 = cross(m[0], m[1]);
  const float n0 = dot(c0, c0), n1 = dot(c1, c1), n2 = dot(c2, c2);
  vec3 v = n0 >= n1 && n0 >= n2 ? c0 : (n1 >= n2 ? c1 : c2);
  v = normalize(v);
  const vec3 w = abs(v);
  const vec3 axis = w.x <= w.y && w.x <= w.z ? vec3(1.0, 0.0, 0.0)
                    : w.y <= w.z             ? vec3(0.0, 1.0, 0.0)
                                             : vec3(0.0, 0.0, 1.0);
  const vec3 b = normalize(cross(v, axis));
  const vec3 c = cross(v, b);
  const vec3 sb = s * b, sc = s * c;
  const float t00 = dot(b, sb), t11 = dot(c, sc), t01 = 0.5 * (dot(b, sc) + dot(c, sb));
  const float mid = 0.5 * (t00 + t11);
  const float half_diff = 0.5 * (t00 - t11);
  const float rad = sqrt(half_diff * half_diff + t01 * t01);
  vec3 e = top ? vec3(l, mid + rad, mid - rad) : vec3(mid + rad, mid - rad, l);
  // The isolated eigenvalue is at least sqrt(3) p from the pair, so this only guards rounding.
  if (e.x < e.y) e.xy = e.yx;
  if (e.y < e.z) e.yz = e.zy;
  if (e.x < e.y) e.xy = e.yx;
  return vec3(q) + scale * e;
}

#endif  // PHYXEL_SYM_EIGEN_GLSL
