// Pointwise pieces of the MLS model shared by the solver shaders; the GLSL twin of
// engine/solver/mls_model.h and engine/solver/kernel.h (see docs/decisions.md for the derivation).
// Include after layout.h.
#ifndef PHYXEL_SOLVER_MLS_GLSL
#define PHYXEL_SOLVER_MLS_GLSL

// A symmetric 3x3 matrix packed in two vec4: (a00 a01 a02 a11), (a12 a22 . .).
mat3 unpack_sym(vec4 a, vec4 b) {
  return mat3(a.x, a.y, a.z, a.y, a.w, b.x, a.z, b.x, b.y);
}

// poly6 weight w = 315 / (64 pi h^3) (1 - r^2 / h^2)^3 for r < h, written with the normalised
// constant of SolverClass.kernel (h^2, 315 / (64 pi h^3)) so it stays in float range for any h.
float poly6_weight(float r2, vec4 kernel) {
  const float q = max(kernel.x - r2, 0.0) / kernel.x;
  return kernel.y * q * q * q;
}

mat3 cofactor(mat3 f) {
  return mat3(cross(f[1], f[2]), cross(f[2], f[0]), cross(f[0], f[1]));
}

// The strain measures of F = I + G, computed from G so that small strains keep their relative
// precision in float (F^T F - I and det F - 1 would cancel): E = (G + G^T + G^T G) / 2 and
// J - 1 = tr G + (sum of the principal 2x2 minors of G) + det G.
struct Strain {
  mat3 f;
  mat3 e;
  float tr_e;
  float j_minus_1;
};

Strain strain_of(mat3 g) {
  Strain s;
  s.f = mat3(1.0) + g;
  s.e = 0.5 * (g + transpose(g) + transpose(g) * g);
  s.tr_e = s.e[0][0] + s.e[1][1] + s.e[2][2];
  const float minors = g[0][0] * g[1][1] - g[1][0] * g[0][1] + g[0][0] * g[2][2] -
                       g[2][0] * g[0][2] + g[1][1] * g[2][2] - g[2][1] * g[1][2];
  s.j_minus_1 = (g[0][0] + g[1][1] + g[2][2]) + minors + determinant(g);
  return s;
}

// First Piola-Kirchhoff stress P = F S + k_v (J - 1) cof F, S = lambda' tr(E) I + 2 mu E;
// elastic = (lambda', mu, k_v).
mat3 first_piola(Strain s, vec3 elastic) {
  const mat3 stress2 = (elastic.x * s.tr_e) * mat3(1.0) + (2.0 * elastic.y) * s.e;
  return s.f * stress2 + (elastic.z * s.j_minus_1) * cofactor(s.f);
}

// Cauchy stress sigma = P F^T / J (P itself where |J| <= 1e-12), as mls_model.h cauchy_stress.
mat3 cauchy_stress(Strain s, mat3 piola) {
  const float j = 1.0 + s.j_minus_1;
  return abs(j) > 1e-12 ? piola * transpose(s.f) / j : piola;
}

// Energy per unit rest volume W = mu E:E + lambda'/2 tr(E)^2 + k_v/2 (J - 1)^2.
float energy_density(Strain s, vec3 elastic) {
  const float ee = dot(s.e[0], s.e[0]) + dot(s.e[1], s.e[1]) + dot(s.e[2], s.e[2]);
  return elastic.y * ee + 0.5 * elastic.x * s.tr_e * s.tr_e +
         0.5 * elastic.z * s.j_minus_1 * s.j_minus_1;
}

// The half kick of velocity Verlet with implicit mass-proportional damping,
// v <- (v + dt/2 f / m) / (1 + c dt/2), in the CPU reference's order of operations. `precise`
// keeps every compiler from fusing it differently in different passes, so a step split over
// two passes (kick; kick + drift) and one fused pass give the same bits.
vec3 half_kick(vec3 v, vec3 f, float mass, float damping, float half_dt) {
  precise vec3 kicked = v + (half_dt / mass) * f;
  precise vec3 out_v = kicked / (1.0 + damping * half_dt);
  return out_v;
}

vec3 drift(vec3 u, vec3 v, float dt) {
  precise vec3 out_u = u + dt * v;
  return out_u;
}

// Whether phyxel i's pair weights come from the pair buffer (see kWeightsAuto in layout.h).
bool stored_weights(uint weights_mode, uint flags) {
  return weights_mode == kWeightsStored || (flags & kFlagPairsEdited) != 0u;
}

bool moves(uint flags) {
  return (flags & (kFlagFixed | kFlagRemoved)) == 0u;
}

#endif  // PHYXEL_SOLVER_MLS_GLSL
