// Von Mises equivalent of the Cauchy stress sigma = P F^T / J per phyxel (P itself where
// |J| <= 1e-12), as engine/solver/mls_model.h von_mises(). Same bindings as solver_energy; vel and
// ext are not read; out is one float per phyxel.
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
// Not read: declared so that the layout equals solver_energy's (Pipeline checks it).
layout(std430, binding = kEnergyBindingVel) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = kEnergyBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kEnergyBindingAinv) readonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kEnergyBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kEnergyBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kEnergyBindingOut) writeonly buffer Out { float von_mises[]; };

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.count) return;
  const uint fl = flags[i];
  const SolverClass cls = classes[fl >> kFlagClassShift];
  const bool stored = stored_weights(p.weights, fl);
  const vec4 li = local_pos[i];
  const vec3 ui = disp[i].xyz;
  mat3 m = mat3(0.0);
  for (uint k = offset[i]; k < offset[i + 1u]; ++k) {
    const uint j = nbr_index(k);
    const vec3 x = local_pos[j].xyz - li.xyz;
    const float w = stored ? pair_weight(k) : poly6_weight(dot(x, x), cls.kernel);
    m += outerProduct(w * (disp[j].xyz - ui), x);
  }
  const mat3 g = m * unpack_sym(ainv[2u * i], ainv[2u * i + 1u]);
  const Strain s = strain_of(g);
  const mat3 sigma = cauchy_stress(s, first_piola(s, cls.elastic.xyz));
  const float mean = (sigma[0][0] + sigma[1][1] + sigma[2][2]) / 3.0;
  const mat3 dev = sigma - mean * mat3(1.0);
  von_mises[i] = sqrt(1.5 * (dot(dev[0], dev[0]) + dot(dev[1], dev[1]) + dot(dev[2], dev[2])));
}
