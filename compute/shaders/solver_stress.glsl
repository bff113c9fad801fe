// The stress pass's arithmetic per phyxel, shared by solver_stress and tool_sever_stress (the
// pass in the sever's dispatch, and the redo of the stress of the phyxels the sever cut pairs
// of: the same expressions, the same bits). Include after solver_mls.glsl and the buffers ainv,
// resid and stress; with PHYXEL_STRESS_GATHER, also after offset, disp, flags, classes,
// stress_list, pair_buffers.glsl, float stress_pair_weight(uint k) and vec4 stress_local(uint x).
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

#ifdef PHYXEL_STRESS_GATHER
// Lane q of a phyxel's lanes sums neighbours q, q + lanes, ...; lane 0 then adds the
// lanes' sums in lane order (a fixed order: reruns are bit-identical).
shared mat3 partial_m[gl_WorkGroupSize.x];

// Invocation `invocation` of the stress pass over stress_list[0, count), `lanes` a phyxel (every
// invocation of the workgroup calls it: a barrier where lanes > 1). Whether it stored D_i (lane
// 0 of a phyxel in the list); then i, s and piola are phyxel i's.
bool stress_pass_phyxel(uint invocation, uint lanes, uint count, uint weights, out uint i,
                        out Strain s, out mat3 piola) {
  const uint slot = invocation / lanes;
  const uint lane = invocation % lanes;
  const bool in_pass = slot < count;
  i = 0u;
  uint fl = 0u;
  SolverClass cls;
  vec4 li = vec4(0.0);
  vec3 ui = vec3(0.0);
  mat3 m = mat3(0.0);
  if (in_pass) {
    i = stress_list[slot];
    fl = flags[i];
    cls = classes[fl >> kFlagClassShift];
    li = stress_local(i);
    ui = disp[i].xyz;
    const bool stored = stored_weights(weights, fl);
    const uint end = offset[i + 1u];
    uint k = offset[i] + lane;
    uint next = k < end ? nbr_index(k) : 0u;
    for (; k < end; k += lanes) {
      const uint j = next;
      if (k + lanes < end) next = nbr_index(k + lanes);  // in flight while j is gathered
      const vec3 x = stress_local(j).xyz - li.xyz;
      const float w = stored ? stress_pair_weight(k) : poly6_weight(dot(x, x), cls.kernel);
      add_stress_pair(m, w, disp[j].xyz - ui, x);
    }
  }
  if (lanes > 1u) {  // uniform: every invocation of the workgroup reaches the barrier
    partial_m[gl_LocalInvocationIndex] = m;
    barrier();
    if (lane != 0u || !in_pass) return false;
    for (uint q = 1u; q < lanes; ++q) m += partial_m[gl_LocalInvocationIndex + q];
  }
  if (!in_pass) return false;
  store_stress(i, fl, cls, li.w, ui, m, s, piola);
  return true;
}
#endif  // PHYXEL_STRESS_GATHER

#endif  // PHYXEL_SOLVER_STRESS_GLSL
