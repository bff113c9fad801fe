// The contact forces of one substep per tool (tool_contact_sum.glsl), one workgroup per tool:
// where tool_resist adds to tool_contact's partials between the two (tool_contact sums them
// itself otherwise, kContactFuseReduce). With p.rows > 0, one workgroup per (row, tool) over
// solver_force_tear's per-candidate rows (kForceContact): each 64 candidates' partial by
// tool_contact's tree, then tool_contact's sum of the partials, so the same bits.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ContactReducePush p; };
layout(std430, binding = kContactReduceBindingForce) readonly buffer Force {
  vec4 contact_force[];
};
layout(std430, binding = kContactReduceBindingSamples) writeonly buffer Samples {
  vec4 samples[];
};
layout(std430, binding = kContactReduceBindingCount) readonly buffer Count { ContactCount count; };
layout(std430, binding = kContactReduceBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kContactReduceBindingFlags) readonly buffer Flags { uint flags[]; };

#include "tool_contact_sum.glsl"

// Row `row` of tool `tool`: thread t adds the partials of workgroups t, t + 64, ... in order,
// as write_tool_sample does. A candidate that the force pass did not visit (fixed or removed
// since the broad phase) takes nothing, as tool_contact's `takes`.
void sum_rows(uint row, uint tool) {
  const uint t = gl_LocalInvocationIndex;
  const uint total = count.total;
  const uint felt_base = (2u * row * p.tools + tool) * p.capacity;
  const uint along_base = ((2u * row + 1u) * p.tools + tool) * p.capacity;
  vec4 sum = vec4(0.0);
  vec2 along = vec2(kNoContactAxial, -kNoContactAxial);
  const uint partials = (total + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
  for (uint k = 0u; k < partials; ++k) {
    const uint slot = k * PHYXEL_WORKGROUP_SIZE + t;
    vec4 felt = vec4(0.0);
    vec2 range = vec2(kNoContactAxial, -kNoContactAxial);
    if (slot < total && (flags[list[slot]] & (kFlagFixed | kFlagRemoved)) == 0u) {
      felt = contact_force[felt_base + slot];
      range = contact_force[along_base + slot].xy;
    }
    sum_workgroup(felt, range);
    if (t == k % PHYXEL_WORKGROUP_SIZE) {
      sum += wg_felt[0];
      along = vec2(min(along.x, wg_along[0].x), max(along.y, wg_along[0].y));
    }
    barrier();  // the next workgroup's sums reuse the shared arrays
  }
  write_sample(sum, along, tool, p.tools, row);
}

void main() {
  const uint g = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (p.rows > 0u) {
    if (g >= p.rows * p.tools) return;  // whole workgroups only, before any barrier
    sum_rows(p.substep + g / p.tools, g % p.tools);
    return;
  }
  if (g >= p.tools) return;
  write_tool_sample(g, p.tools, p.capacity, p.substep, count.total);
}
