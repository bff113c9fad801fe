// The regularised inverse of a moment matrix A = sum_j w x x^T: the GLSL twin of
// regularised_inverse() in engine/solver/mls_model.h, shared by the solver's precompute
// (solver_precompute.comp) and the renderer's deform pass (render/shaders/deform_surfels.comp),
// so that a splat's F = I + grad u is the solver's. A is decomposed by cyclic Jacobi; where its
// condition number exceeds kMaxCondition (too few, coplanar or collinear neighbours, typically
// after a cut) the small eigenvalues are raised to lambda_max / kMaxCondition.
#ifndef PHYXEL_MOMENT_INVERSE_GLSL
#define PHYXEL_MOMENT_INVERSE_GLSL

const float kMaxCondition = 100.0;  // engine/solver/mls_model.h kMaxMomentCondition

// One Jacobi rotation in the (a, b) plane that zeroes m[a][b]; q accumulates the eigenvectors.
void jacobi_rotate(inout mat3 m, inout mat3 q, int a, int b) {
  const float mab = m[b][a];
  if (mab == 0.0) return;
  const float theta = (m[b][b] - m[a][a]) / (2.0 * mab);
  const float t =
      theta == 0.0 ? 1.0 : sign(theta) / (abs(theta) + sqrt(theta * theta + 1.0));
  const float c = inversesqrt(t * t + 1.0);
  const float s = t * c;
  mat3 r = mat3(1.0);
  r[a][a] = c;
  r[b][b] = c;
  r[b][a] = s;   // row a, column b
  r[a][b] = -s;  // row b, column a
  m = transpose(r) * m * r;
  m[b][a] = 0.0;
  m[a][b] = 0.0;
  q = q * r;
}

// The eigenvalues of a symmetric a (cyclic Jacobi: a few sweeps bring a 3x3 matrix to float
// round-off); q accumulates the eigenvectors.
vec3 jacobi_eigen(mat3 a, out mat3 q) {
  mat3 d = a;
  q = mat3(1.0);
  for (int sweep = 0; sweep < 8; ++sweep) {
    const float off = d[1][0] * d[1][0] + d[2][0] * d[2][0] + d[2][1] * d[2][1];
    const float diag = d[0][0] * d[0][0] + d[1][1] * d[1][1] + d[2][2] * d[2][2];
    if (off <= 1e-14 * diag) break;
    jacobi_rotate(d, q, 0, 1);
    jacobi_rotate(d, q, 0, 2);
    jacobi_rotate(d, q, 1, 2);
  }
  return vec3(d[0][0], d[1][1], d[2][2]);
}

struct MomentInverse {
  mat3 inverse;      // 0 where A has no weight at all (no gradient information)
  mat3 residual;     // A^-1 A A^-1 - A^-1: 0 unless regularised
  float lambda_min;  // of A itself
  bool regularised;  // also where A is 0
};

MomentInverse regularised_inverse(mat3 a) {
  MomentInverse result;
  mat3 q;
  vec3 lambda = jacobi_eigen(a, q);
  const float lmax = max(lambda.x, max(lambda.y, lambda.z));
  result.lambda_min = min(lambda.x, min(lambda.y, lambda.z));
  result.inverse = mat3(0.0);
  result.residual = mat3(0.0);
  result.regularised = true;
  if (lmax > 0.0) {
    result.regularised = !(result.lambda_min > 0.0) || lmax / result.lambda_min > kMaxCondition;
    if (result.regularised) lambda = max(lambda, vec3(lmax / kMaxCondition));
    result.inverse =
        q * mat3(1.0 / lambda.x, 0, 0, 0, 1.0 / lambda.y, 0, 0, 0, 1.0 / lambda.z) * transpose(q);
    if (result.regularised)
      result.residual = result.inverse * a * result.inverse - result.inverse;
  }
  return result;
}

#endif  // PHYXEL_MOMENT_INVERSE_GLSL
