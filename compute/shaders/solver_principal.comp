// The largest principal value of the Cauchy stress sigma = P F^T / J (P itself where
// |J| <= 1e-12) per phyxel of the stress pass list, for tearing: engine/solver/mls_model.h
// max_principal_stress() and engine/solver/cpu_solver.cpp compute_forces(). Recorded after
// every stress pass while GpuSolver::set_principal_stress is on; reads the same u.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "solver_mls.glsl"
#include "sym_eigen.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { StepPush p; };
layout(std430, binding = kPrincipalBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kPrincipalBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kPrincipalBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kPrincipalBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kPrincipalBindingWeightHi
#define PHYXEL_PAIR_ACCESS 0
#include "pair_buffers.glsl"
layout(std430, binding = kPrincipalBindingLocal) readonly buffer Local { vec4 local_pos[]; };
layout(std430, binding = kPrincipalBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kPrincipalBindingAinv) readonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kPrincipalBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kPrincipalBindingClasses) readonly buffer Classes {
  SolverClass classes[];
};
layout(std430, binding = kPrincipalBindingOut) writeonly buffer Out { float max_principal[]; };
layout(std430, binding = kPrincipalBindingList) readonly buffer List { uint pass_list[]; };
layout(std430, binding = kPrincipalBindingCauchy) writeonly buffer Cauchy { vec4 cauchy[]; };

// Lane q of a phyxel's lanes sums neighbours q, q + lanes, ...; lane 0 adds them in lane order.
shared mat3 partial_m[PHYXEL_WORKGROUP_SIZE];

void main() {
  const uint lanes = p.lanes;
  const uint invocation = PHYXEL_GLOBAL_INDEX;
  const uint slot = invocation / lanes;
  const uint lane = invocation % lanes;
  const bool in_pass = slot < p.count;
  uint i = 0u;
  SolverClass cls;
  mat3 m = mat3(0.0);
  if (in_pass) {
    i = pass_list[slot];
    const uint fl = flags[i];
    cls = classes[fl >> kFlagClassShift];
    const bool stored = stored_weights(p.weights, fl);
    const vec4 li = local_pos[i];
    const vec3 ui = disp[i].xyz;
    const uint end = offset[i + 1u];
    for (uint k = offset[i] + lane; k < end; k += lanes) {
      const uint j = nbr_index(k);
      const vec3 x = local_pos[j].xyz - li.xyz;
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
  const mat3 g = m * unpack_sym(ainv[2u * i], ainv[2u * i + 1u]);
  const Strain s = strain_of(g);
  const mat3 sigma = cauchy_stress(s, first_piola(s, cls.elastic.xyz));
  const mat3 sym = 0.5 * (sigma + transpose(sigma));
  max_principal[i] = sym_eigenvalues(sym).x;
  if (p.mode == kPrincipalWithTensor) {  // tearing: solver_tear reads the tensor
    cauchy[2u * i] = vec4(sym[0][0], sym[1][1], sym[2][2], sym[1][0]);
    cauchy[2u * i + 1u] = vec4(sym[2][0], sym[2][1], 0.0, 0.0);
  }
}
