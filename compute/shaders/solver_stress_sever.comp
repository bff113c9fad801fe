// The cut pass and the stress pass after it in one dispatch (StressSeverPush in
// layout_surgery.h; GpuSolverOptions::sever_in_stress): workgroups [0, stress_groups) run
// solver_stress.comp's gather over the stress list, the rest tool_sever.comp's tests over the
// broad phase's candidates (lanes per candidate as many as the workgroups hold, a grid-stride
// loop past that: the same pairs are severed in any order). A cut changes the weights, the
// precompute and so the stress of the two phyxels of each pair it severs, and nothing of any
// other phyxel's stress (a phyxel's stress reads only its own row, A^-1, residual, kappa and
// flags); the workgroup that finishes last reruns the precompute of the dirty list and then the
// stress of those phyxels from what the cut left: the bits of tool_sever then solver_stress.
// The dirty phyxels are in the stress list: each is a candidate (in the force list) or a live
// neighbour of one.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { StressSeverPush p; };
layout(std430, binding = kSeverBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kSeverBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kSeverBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kSeverBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kSeverBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kSeverBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kSeverBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kSeverBindingWeightHi
#define PHYXEL_PAIR_ACCESS 2
#define PHYXEL_PAIR_WEIGHT_COHERENT
#include "pair_buffers.glsl"
// Coherent: the last workgroup reads what the others wrote (flags, weights, the dirty list, the
// stress it overwrites) and, between its precompute and its stress, what its own lanes wrote.
layout(std430, binding = kSeverBindingFlags) coherent buffer Flags { uint flags[]; };
layout(std430, binding = kSeverBindingQuads) readonly buffer Quads { CutQuad quads[]; };
layout(std430, binding = kSeverBindingSamples) readonly buffer Samples { vec4 samples[]; };
layout(std430, binding = kSeverBindingDirty) coherent buffer Dirty { uint dirty[]; };
layout(std430, binding = kSeverBindingLog) buffer Log { uvec4 cut_log[]; };
layout(std430, binding = kSeverBindingCount) readonly buffer Count {
  ContactCount count;
  SeverGroups sever;
};
layout(std430, binding = kSeverBindingLocal) coherent buffer Local { vec4 local_pos[]; };
layout(std430, binding = kStressSeverBindingLocalRest) readonly buffer LocalRest {
  vec4 local_rest[];
};
layout(std430, binding = kSeverBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kSeverBindingAinv) coherent buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kSeverBindingResid) coherent buffer Resid { vec4 resid[]; };
layout(std430, binding = kSeverBindingDone) coherent buffer Done { uint done; };
layout(std430, binding = kStressSeverBindingList) readonly buffer StressList { uint pass_list[]; };
layout(std430, binding = kStressSeverBindingStress) coherent writeonly buffer Stress {
  vec4 stress[];
};
layout(std430, binding = kStressSeverBindingPrincipal) coherent writeonly buffer Principal {
  float max_principal[];
};
layout(std430, binding = kStressSeverBindingCauchy) coherent writeonly buffer Cauchy {
  vec4 cauchy[];
};

#include "tool_sever.glsl"
#define PHYXEL_STRESS_NEIGHBOUR_LOCAL local_rest
#include "solver_stress.glsl"

// The sever workgroups: every candidate's pairs, `lanes` invocations per candidate.
void sever_candidates(uint first, uint threads) {
  if (!any_tool_severs()) return;  // every invocation of the workgroup: a barrier inside
  const uint total = count.total;
  uint lanes = kSeverMaxLanes;
  while (lanes > 1u && total * lanes > threads) lanes /= 2u;
  for (uint s = first; s < total * lanes; s += threads) {
    const uint i = list[s / lanes];
    const vec3 xi = rest[i].xyz - p.origin.xyz + disp[i].xyz;
    const uint end = offset[i + 1u];
    for (uint k = offset[i] + s % lanes; k < end; k += lanes) sever_pair(i, xi, k);
  }
}

// The last workgroup, after the precompute: the stress of the dirty list's phyxels, p.lanes
// invocations each as in the stress workgroups (the same sums in the same order).
void restress_dirty_list() {
  const uint dirtied = dirty[0];
  const uint lanes = p.lanes;
  const uint per = gl_WorkGroupSize.x / lanes;
  const uint t = gl_LocalInvocationIndex;
  for (uint base = 0u; base < dirtied; base += per) {
    memoryBarrierBuffer();
    barrier();  // the precompute's writes, and the round before's partial sums read
    const uint e = base + t / lanes;
    stress_of(e < dirtied, e < dirtied ? dirty[1u + e] : 0u, t % lanes, lanes);
  }
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  const uint t = gl_LocalInvocationIndex;
  if (group < p.stress_groups) {
    const uint invocation = group * gl_WorkGroupSize.x + t;
    const uint slot = invocation / p.lanes;
    const bool in_pass = slot < p.count;
    stress_of(in_pass, in_pass ? pass_list[slot] : 0u, invocation % p.lanes, p.lanes);
  } else {
    const uint groups = gl_NumWorkGroups.x * gl_NumWorkGroups.y - p.stress_groups;
    sever_candidates((group - p.stress_groups) * gl_WorkGroupSize.x + t,
                     groups * gl_WorkGroupSize.x);
  }
  if (finished_last()) {
    precompute_listed();
    restress_dirty_list();
  }
}
