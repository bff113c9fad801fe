// Aspiration's reads without the whole state (layout.h NearPush): the phyxels in a box with
// their u and largest principal stress (modes 0 and 1, with tool_broad_scan between them, as
// the contact broad phase: the hits come out ascending), or those of a list of ids (mode 2).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { NearPush p; };
layout(std430, binding = kNearBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kNearBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kNearBindingPrincipal) readonly buffer Principal { float principal[]; };
layout(std430, binding = kNearBindingGroup) buffer Group { uint group[]; };
layout(std430, binding = kNearBindingIds) buffer Ids { uint ids[]; };
layout(std430, binding = kNearBindingOut) writeonly buffer Out { vec4 out_state[]; };

shared uint rank[PHYXEL_WORKGROUP_SIZE];

vec4 state_of(uint i) {
  return vec4(disp[i].xyz, p.principal != 0u ? principal[i] : 0.0);
}

void main() {
  if (p.mode == 2u) {
    const uint k = PHYXEL_GLOBAL_INDEX;
    if (k < p.count) out_state[k] = state_of(ids[k]);
    return;
  }
  const uint g = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (g >= p.groups) return;  // whole workgroups only, before any barrier
  const uint t = gl_LocalInvocationID.x;
  const uint i = g * PHYXEL_WORKGROUP_SIZE + t;
  bool hit = false;
  if (i < p.count) {
    const vec3 x = rest[i].xyz + disp[i].xyz;
    hit = all(greaterThanEqual(x, p.lo.xyz)) && all(lessThanEqual(x, p.hi.xyz));
  }
  // Inclusive scan of the hits over the workgroup (Hillis-Steele, fixed order).
  rank[t] = hit ? 1u : 0u;
  barrier();
  for (uint d = 1u; d < PHYXEL_WORKGROUP_SIZE; d <<= 1u) {
    const uint add = t >= d ? rank[t - d] : 0u;
    barrier();
    rank[t] += add;
    barrier();
  }
  if (p.mode == 0u) {
    if (t == PHYXEL_WORKGROUP_SIZE - 1u) group[g] = rank[t];
  } else if (hit) {
    const uint at = group[g] + rank[t] - 1u;
    ids[at] = i;
    out_state[at] = state_of(i);
  }
}
