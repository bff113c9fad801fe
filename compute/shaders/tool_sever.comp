// Cutting after a substep's contacts (SeverPush in layout_surgery.h; the CPU twin is
// CpuSolver::apply_cuts in engine/solver/cpu_solver_cutting.cpp): SeverGroups.lanes invocations
// per candidate, each taking every lanes-th of its live pairs, test each pair against the quad
// each cutting blade swept, in the canonical order (lower index first) with the tie rule of
// engine/solver/cutting.cpp (an endpoint on the plane is on the positive side; a segment through
// an edge crosses, except through the front), and the pairs its edge holds (blade_edge.glsl);
// whatever the force, the pairs a blade's edge carries past its reach (edge_passes).
// A pair goes to the first tool that crosses it (the CPU's tool by tool: a later tool finds it
// severed); no pair's test reads another's outcome, so the same pairs are severed with the same
// t in any order. A pair is tested against a blade only where its segment meets the ball around
// all that blade can sever this substep (blade_ball). Then the workgroup that finishes last
// reruns the precompute of the phyxels put in the dirty list (none most substeps: no dependent
// dispatch; kSeverWorkgroupSize lanes, several per phyxel for a short list). Positions relative
// to the motion table's origin.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = kSeverWorkgroupSize) in;

layout(push_constant) uniform Push { SeverPush p; };
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
// Coherent: the last workgroup reads the flags, weights and list that the others wrote.
layout(std430, binding = kSeverBindingFlags) coherent buffer Flags { uint flags[]; };
layout(std430, binding = kSeverBindingQuads) readonly buffer Quads { CutQuad quads[]; };
layout(std430, binding = kSeverBindingSamples) readonly buffer Samples { vec4 samples[]; };
layout(std430, binding = kSeverBindingDirty) coherent buffer Dirty { uint dirty[]; };
layout(std430, binding = kSeverBindingLog) buffer Log { uvec4 cut_log[]; };
layout(std430, binding = kSeverBindingCount) readonly buffer Count {
  ContactCount count;
  SeverGroups sever;  // tool_broad_scan's: the lanes per candidate
};
layout(std430, binding = kSeverBindingLocal) buffer Local { vec4 local_pos[]; };
layout(std430, binding = kSeverBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kSeverBindingAinv) writeonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kSeverBindingResid) writeonly buffer Resid { vec4 resid[]; };
layout(std430, binding = kSeverBindingDone) coherent buffer Done { uint done; };

#include "tool_sever.glsl"

void main() {
  const uint invocation = PHYXEL_GLOBAL_INDEX;
  const uint lanes = sever.lanes;
  const uint slot = invocation / lanes;
  if (any_tool_severs() && slot < count.total) {
    const uint i = list[slot];
    const vec3 xi = rest[i].xyz - p.origin.xyz + disp[i].xyz;
    const uint end = offset[i + 1u];
    for (uint k = offset[i] + invocation % lanes; k < end; k += lanes)
      sever_pair(i, xi, k);
  }
  precompute_dirty_list();
}
