// Per phyxel (all or a list), solver_precompute.glsl's moment matrix, its
// regularised inverse and residual, and the hourglass stiffness, from the stored pair weights.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { PrecomputePush p; };
layout(std430, binding = kPrecomputeBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kPrecomputeBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kPrecomputeBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kPrecomputeBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kPrecomputeBindingWeightHi
#define PHYXEL_PAIR_ACCESS 0
#include "pair_buffers.glsl"
layout(std430, binding = kPrecomputeBindingLocal) buffer Local { vec4 local_pos[]; };
layout(std430, binding = kPrecomputeBindingFlags) buffer Flags { uint flags[]; };
layout(std430, binding = kPrecomputeBindingClasses) readonly buffer Classes {
  SolverClass classes[];
};
layout(std430, binding = kPrecomputeBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kPrecomputeBindingAinv) writeonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kPrecomputeBindingResid) writeonly buffer Resid { vec4 resid[]; };
layout(std430, binding = kPrecomputeBindingList) readonly buffer List { uint list[]; };

#include "solver_precompute.glsl"

void main() {
  const uint invocation = PHYXEL_GLOBAL_INDEX;
  if (invocation >= p.count) return;
  precompute_phyxel(p.indexed != 0u ? list[invocation] : p.first + invocation, false);
}
