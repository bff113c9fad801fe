// The contact broad phase of a chunk over the force list (layout.h BroadPhasePush): mode 0
// counts each workgroup's hits into group[g], with kBroadBladeNear where one lies within the
// blades' swept bounds grown by the margin (CpuSolver::find_candidates' blades_near_); mode 1
// (after tool_broad_scan turned the counts into offsets) writes the hits at group[g] + their
// rank in the workgroup, and each entry's slot (~0: none) into candidate_slot
// (solver_force_tear's contact). Both modes decide a hit from the same inputs, so they agree;
// the list comes out ascending.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { BroadPhasePush p; };
layout(std430, binding = kBroadBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kBroadBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kBroadBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kBroadBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kBroadBindingMaxNorm) readonly buffer MaxNorm { vec4 max_norm; };
layout(std430, binding = kBroadBindingGroup) buffer Group { uint group[]; };
layout(std430, binding = kBroadBindingOut) writeonly buffer Out { uint candidates[]; };
layout(std430, binding = kBroadBindingSlot) writeonly buffer Slot { uint candidate_slot[]; };

shared uint rank[PHYXEL_WORKGROUP_SIZE];
shared uint blade_near;  // kBroadBladeNear where a hit lies within the blades' reach

bool inside(vec3 x, vec3 lo, vec3 hi, float margin) {
  return all(greaterThanEqual(x, lo - margin)) && all(lessThanEqual(x, hi + margin));
}

void main() {
  const uint g = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (g >= p.groups) return;  // whole workgroups only, before any barrier
  const uint t = gl_LocalInvocationID.x;
  const uint slot = g * PHYXEL_WORKGROUP_SIZE + t;
  bool hit = false, near = false;
  uint i = 0u;
  if (t == 0u) blade_near = 0u;
  if (slot < p.count) {
    i = list[slot];
    // contact_margin: 2 duration max(max|v|, tool speed) + spacing
    const float margin = 2.0 * p.hi.w * max(max_norm.y, p.tool_speed) + p.lo.w;
    const vec3 x = rest[i].xyz + disp[i].xyz;
    // A non-finite margin (a diverging run) takes every phyxel, as contact_candidates does.
    const bool all_in = isnan(margin) || isinf(margin);
    hit = (flags[i] & (kFlagFixed | kFlagRemoved)) == 0u &&
          (all_in || inside(x, p.lo.xyz, p.hi.xyz, margin));
    near = hit && (all_in || p.blade_lo.w != 0.0 ||
                   inside(x, p.blade_lo.xyz, p.blade_hi.xyz, margin));
  }
  // Inclusive scan of the hits over the workgroup (Hillis-Steele, fixed order).
  rank[t] = hit ? 1u : 0u;
  barrier();  // blade_near's reset
  if (near) atomicOr(blade_near, kBroadBladeNear);
  for (uint d = 1u; d < PHYXEL_WORKGROUP_SIZE; d <<= 1u) {
    const uint add = t >= d ? rank[t - d] : 0u;
    barrier();
    rank[t] += add;
    barrier();
  }
  if (p.mode == 0u) {
    if (t == PHYXEL_WORKGROUP_SIZE - 1u) group[g] = rank[t] | blade_near;
  } else if (slot < p.count) {
    // Every phyxel of the list gets its slot (or none), for solver_force_tear's contact.
    const uint at = group[g] + rank[t] - 1u;
    if (hit) candidates[at] = i;
    candidate_slot[i] = hit ? at : 0xFFFFFFFFu;
  }
}
