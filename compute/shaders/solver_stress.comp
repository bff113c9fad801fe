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
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "solver_mls.glsl"
#include "sym_eigen.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { StepPush p; };
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
layout(std430, binding = kStressBindingStress) writeonly buffer Stress { vec4 stress[]; };
layout(std430, binding = kStressBindingList) readonly buffer List { uint stress_list[]; };
layout(std430, binding = kStressBindingPrincipal) writeonly buffer Principal {
  float max_principal[];
};
layout(std430, binding = kStressBindingCauchy) writeonly buffer Cauchy { vec4 cauchy[]; };

float stress_pair_weight(uint k) {
  return pair_weight(k);
}

vec4 stress_local(uint x) {
  return local_pos[x];
}

#define PHYXEL_STRESS_GATHER
#include "solver_stress.glsl"

void main() {
  uint i;
  Strain s;
  mat3 piola;
  if (!stress_pass_phyxel(PHYXEL_GLOBAL_INDEX, p.lanes, p.count, p.weights, i, s, piola)) return;
  if (p.mode == kStressOnly) return;
  const mat3 sigma = cauchy_stress(s, piola);
  const mat3 sym = 0.5 * (sigma + transpose(sigma));
  max_principal[i] = sym_eigenvalues(sym).x;
  if (p.mode == kStressWithTensor) {
    cauchy[2u * i] = vec4(sym[0][0], sym[1][1], sym[2][2], sym[1][0]);
    cauchy[2u * i + 1u] = vec4(sym[2][0], sym[2][1], 0.0, 0.0);
  }
}
