// Per phyxel i: (strain, kinetic, potential, 0) with
//   strain    = v_i W(F_i) + kappa_i / 2 sum_j w_ij |G_i x_ij - (u_j - u_i)|^2,
//   kinetic   = m_i |v_i|^2 / 2,   potential = -ext_i . u_i
// (engine/solver/cpu_solver.cpp, internal_energy() and energies()). solver_reduce sums them.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "solver_mls.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { StepPush p; };
layout(std430, binding = kEnergyBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kEnergyBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kEnergyBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kEnergyBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kEnergyBindingWeightHi
#define PHYXEL_PAIR_ACCESS 0
#include "pair_buffers.glsl"
layout(std430, binding = kEnergyBindingLocal) readonly buffer Local { vec4 local_pos[]; };
layout(std430, binding = kEnergyBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kEnergyBindingVel) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = kEnergyBindingAinv) readonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kEnergyBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kEnergyBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kEnergyBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kEnergyBindingOut) writeonly buffer Out { vec4 energy[]; };

float weight_of(bool stored, uint k, vec3 x, vec4 kernel) {
  return stored ? pair_weight(k) : poly6_weight(dot(x, x), kernel);
}

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.count) return;
  const uint fl = flags[i];
  const SolverClass cls = classes[fl >> kFlagClassShift];
  const bool stored = stored_weights(p.weights, fl);
  const vec4 li = local_pos[i];
  const vec3 ui = disp[i].xyz;
  const uint begin = offset[i];
  const uint end = offset[i + 1u];
  mat3 m = mat3(0.0);
  for (uint k = begin; k < end; ++k) {
    const uint j = nbr_index(k);
    const vec3 x = local_pos[j].xyz - li.xyz;
    m += outerProduct(weight_of(stored, k, x, cls.kernel) * (disp[j].xyz - ui), x);
  }
  const vec4 a1 = ainv[2u * i + 1u];
  const mat3 g = m * unpack_sym(ainv[2u * i], a1);
  float hourglass = 0.0;
  for (uint k = begin; k < end; ++k) {
    const uint j = nbr_index(k);
    const vec3 x = local_pos[j].xyz - li.xyz;
    const vec3 e = g * x - (disp[j].xyz - ui);
    hourglass += weight_of(stored, k, x, cls.kernel) * dot(e, e);
  }
  const float strain =
      a1.z * energy_density(strain_of(g), cls.elastic.xyz) + 0.5 * li.w * hourglass;
  const vec4 ex = ext[i];
  const vec3 v = vel[i].xyz;
  energy[i] = vec4(strain, 0.5 * ex.w * dot(v, v), -dot(ex.xyz, ui), 0.0);
}
