// The stress pass's arithmetic per phyxel, shared by solver_stress and tool_sever's redo of the
// stress of the phyxels it severed pairs of beside that pass (the same expressions: the same
// bits). Include after solver_mls.glsl and the buffers ainv, resid and stress.
#ifndef PHYXEL_SOLVER_STRESS_GLSL
#define PHYXEL_SOLVER_STRESS_GLSL

// Neighbour j's term of M = sum_j w_ij (u_j - u_i) x_ij^T.
void add_stress_pair(inout mat3 m, float w, vec3 du, vec3 x) {
  m += outerProduct(w * du, x);
}

// D_i from M (flags fl, kappa, u_i as read), stored as three vec4 whose w carry u_i; the strain
// and P for the principal stress.
void store_stress(uint i, uint fl, SolverClass cls, float kappa, vec3 ui, mat3 m, out Strain s,
                  out mat3 piola) {
  const vec4 a0 = ainv[2u * i];
  const vec4 a1 = ainv[2u * i + 1u];
  const mat3 a_inv = unpack_sym(a0, a1);
  const mat3 g = m * a_inv;
  s = strain_of(g);
  piola = first_piola(s, cls.elastic.xyz);
  mat3 d = (a1.z * piola) * a_inv - kappa * g;
  if ((fl & kFlagRegularised) != 0u)
    d += kappa * (m * unpack_sym(resid[2u * i], resid[2u * i + 1u]));
  stress[3u * i] = vec4(d[0], ui.x);
  stress[3u * i + 1u] = vec4(d[1], ui.y);
  stress[3u * i + 2u] = vec4(d[2], ui.z);
}

#endif  // PHYXEL_SOLVER_STRESS_GLSL
