// Step pass 1, per phyxel i of the stress pass list (a gather over its neighbours, by p.lanes
// invocations):
//   M = sum_j w_ij (u_j - u_i) x_ij^T, G = M A^-1, F = I + G,
//   D_i = v_i P(F) A^-1 - kappa_i G (+ kappa_i M R_i where A_i was regularised),
// stored as three vec4 columns whose fourth components carry u_i, the displacement this pass
// read: the force pass gathers D_j and u_j of a neighbour in the same three loads. With mode
// kStressWithPrincipal (tearing possible) it also writes the largest principal value of the
// Cauchy stress sigma = P F^T / J (P itself where |J| <= 1e-12), and with kStressWithTensor the
// symmetrised tensor for solver_force_tear: one gather of grad u for both (mls_model.h
// max_principal_stress()). See engine/solver/cpu_solver.cpp, compute_forces(), first loop.
// With epoch != 0 (tool_sever beside it) each workgroup counts itself in Done once its
// stress is written, by an atomic whose result it does not wait for (not the last workgroup's
// election: that round trip cost the pass about 1 us at breast K = 1).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "solver_mls.glsl"
#include "sym_eigen.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push {
  StepPush p;
  uint epoch;
};
layout(std430, binding = kStressBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kStressBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kStressBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kStressBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kStressBindingWeightHi
#define PHYXEL_PAIR_ACCESS 0
#include "pair_buffers.glsl"
layout(std430, binding = kStressBindingLocal) readonly buffer Local { vec4 local_pos[]; };
layout(std430, binding = kStressBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kStressBindingAinv) readonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kStressBindingResid) readonly buffer Resid { vec4 resid[]; };
layout(std430, binding = kStressBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kStressBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kStressBindingStress) coherent writeonly buffer Stress { vec4 stress[]; };
layout(std430, binding = kStressBindingList) readonly buffer List { uint pass_list[]; };
layout(std430, binding = kStressBindingPrincipal) writeonly buffer Principal {
  float max_principal[];
};
layout(std430, binding = kStressBindingCauchy) writeonly buffer Cauchy { vec4 cauchy[]; };
layout(std430, binding = kStressBindingDone) coherent buffer Done {
  uint finished;  // the workgroups of this advance's passes beside a sever that are written
};

#include "solver_stress.glsl"

// Lane q of a phyxel's lanes sums neighbours q, q + lanes, ...; lane 0 then adds the
// lanes' sums in lane order (a fixed order: reruns are bit-identical).
shared mat3 partial_m[PHYXEL_WORKGROUP_SIZE];

void stress_phyxel() {
  const uint lanes = p.lanes;
  const uint invocation = PHYXEL_GLOBAL_INDEX;
  const uint slot = invocation / lanes;
  const uint lane = invocation % lanes;
  const bool in_pass = slot < p.count;
  uint i = 0u, fl = 0u;
  SolverClass cls;
  vec4 li = vec4(0.0);
  vec3 ui = vec3(0.0);
  mat3 m = mat3(0.0);
  if (in_pass) {
    i = pass_list[slot];
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
      const vec3 x = local_pos[j].xyz - li.xyz;
      const float w = stored ? pair_weight(k) : poly6_weight(dot(x, x), cls.kernel);
      add_stress_pair(m, w, disp[j].xyz - ui, x);
    }
  }
  if (lanes > 1u) {  // uniform: every invocation of the workgroup reaches the barrier
    partial_m[gl_LocalInvocationIndex] = m;
    barrier();
    if (lane != 0u || !in_pass) return;
    for (uint q = 1u; q < lanes; ++q) m += partial_m[gl_LocalInvocationIndex + q];
  }
  if (!in_pass) return;
  Strain s;
  mat3 piola;
  store_stress(i, fl, cls, li.w, ui, m, s, piola);
  if (p.mode == kStressOnly) return;
  const mat3 sigma = cauchy_stress(s, piola);
  const mat3 sym = 0.5 * (sigma + transpose(sigma));
  max_principal[i] = sym_eigenvalues(sym).x;
  if (p.mode == kStressWithTensor) {
    cauchy[2u * i] = vec4(sym[0][0], sym[1][1], sym[2][2], sym[1][0]);
    cauchy[2u * i + 1u] = vec4(sym[2][0], sym[2][1], 0.0, 0.0);
  }
}

void main() {
  stress_phyxel();
  if (epoch != 0u) {  // uniform: every invocation reaches the barrier
    memoryBarrierBuffer();  // this invocation's stress before the count
    barrier();
    if (gl_LocalInvocationIndex == 0u) atomicAdd(finished, 1u);
  }
}
