// The stress pass's gather and stress of one phyxel (solver_stress.comp's, and for the
// phyxels a cut touched, the last workgroup of solver_stress_sever.comp's): lane `lane` of
// `lanes` invocations of phyxel i (in_pass false: an idle lane that still meets the barrier).
// Include after the buffers offset, local_pos, disp, ainv, resid, flags, classes, stress,
// max_principal and cauchy, pair_buffers.glsl and the push constant p (mode, weights).
#ifndef PHYXEL_SOLVER_STRESS_GLSL
#define PHYXEL_SOLVER_STRESS_GLSL

#include "solver_mls.glsl"
#include "sym_eigen.glsl"

// The buffer the neighbours' rest positions are gathered from (local_pos.xyz, which no pass
// writes; solver_stress_sever reads them through a non-coherent alias).
#ifndef PHYXEL_STRESS_NEIGHBOUR_LOCAL
#define PHYXEL_STRESS_NEIGHBOUR_LOCAL local_pos
#endif

// Lane q of a phyxel's lanes sums neighbours q, q + lanes, ...; lane 0 then adds the
// lanes' sums in lane order (a fixed order: reruns are bit-identical).
shared mat3 partial_m[PHYXEL_WORKGROUP_SIZE];

void stress_of(bool in_pass, uint i, uint lane, uint lanes) {
  uint fl = 0u;
  SolverClass cls;
  vec4 li = vec4(0.0);
  vec3 ui = vec3(0.0);
  mat3 m = mat3(0.0);
  if (in_pass) {
    fl = flags[i];
    cls = classes[fl >> kFlagClassShift];
    li = local_pos[i];
    ui = disp[i].xyz;
    const bool stored = stored_weights(p.weights, fl);
    const uint end = offset[i + 1u];
    uint k = offset[i] + lane;
    uint next = k < end ? nbr_index(k) : 0u;
    for (; k < end; k += lanes) {
      const uint j = next;
      if (k + lanes < end) next = nbr_index(k + lanes);  // in flight while j is gathered
      const vec3 x = PHYXEL_STRESS_NEIGHBOUR_LOCAL[j].xyz - li.xyz;
      const float w = stored ? pair_weight(k) : poly6_weight(dot(x, x), cls.kernel);
      m += outerProduct(w * (disp[j].xyz - ui), x);
    }
  }
  if (lanes > 1u) {  // uniform: every invocation of the workgroup reaches the barrier
    partial_m[gl_LocalInvocationIndex] = m;
    barrier();
    if (lane != 0u || !in_pass) return;
    for (uint q = 1u; q < lanes; ++q) m += partial_m[gl_LocalInvocationIndex + q];
  }
  if (!in_pass) return;
  const vec4 a0 = ainv[2u * i];
  const vec4 a1 = ainv[2u * i + 1u];
  const mat3 a_inv = unpack_sym(a0, a1);
  const mat3 g = m * a_inv;
  const Strain s = strain_of(g);
  const mat3 piola = first_piola(s, cls.elastic.xyz);
  const float kappa = li.w;
  mat3 d = (a1.z * piola) * a_inv - kappa * g;
  if ((fl & kFlagRegularised) != 0u)
    d += kappa * (m * unpack_sym(resid[2u * i], resid[2u * i + 1u]));
  stress[3u * i] = vec4(d[0], ui.x);
  stress[3u * i + 1u] = vec4(d[1], ui.y);
  stress[3u * i + 2u] = vec4(d[2], ui.z);
  if (p.mode == kStressOnly) return;
  const mat3 sigma = cauchy_stress(s, piola);
  const mat3 sym = 0.5 * (sigma + transpose(sigma));
  max_principal[i] = sym_eigenvalues(sym).x;
  if (p.mode == kStressWithTensor) {
    cauchy[2u * i] = vec4(sym[0][0], sym[1][1], sym[2][2], sym[1][0]);
    cauchy[2u * i + 1u] = vec4(sym[2][0], sym[2][1], 0.0, 0.0);
  }
}

#endif  // PHYXEL_SOLVER_STRESS_GLSL
