// The contact forces of one substep per tool (tool_contact_sum.glsl), one workgroup per tool:
// where tool_resist adds to tool_contact's partials between the two (tool_contact sums them
// itself otherwise, kContactFuseReduce), or beside the next pass where nothing in the substep
// reads the sample (GpuSolver::sums_apart), then with p.grasp a tool, that grasper's grip
// forces subtracted after (grip_reduce.glsl, as tool_contact's last workgroup). With p.rows > 0, solver_force_tear's per-candidate
// rows (kForceContact) in two dispatches, all rows at once: p.sums 0, one workgroup per (row,
// tool, 64 candidates) writes that partial by tool_contact's tree, as tool_contact writes its
// own; p.sums 1, one workgroup per (row, tool) adds them as tool_contact does, then with p.grasp
// a tool, subtracts that grasper's grip row (GripForce: the grip rows, laid out as the samples).
// The grip rows (p.rows 0, p.sums kContactReduceGripRow, Samples: the grip rows): one workgroup
// writes the grasper's grip sum of substep p.substep, held by solver_force_contact, before the
// next force pass overwrites the grip's forces. The same bits.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push {
  ContactReducePush p;
};
layout(std430, binding = kContactReduceBindingForce) readonly buffer Force {
  vec4 contact_force[];
};
layout(std430, binding = kContactReduceBindingSamples) buffer Samples {
  vec4 samples[];
};
layout(std430, binding = kContactReduceBindingCount) readonly buffer Count {
  ContactCount count;
};
layout(std430, binding = kContactReduceBindingList) readonly buffer List {
  uint list[];
};
layout(std430, binding = kContactReduceBindingFlags) readonly buffer Flags {
  uint flags[];
};
layout(std430, binding = kContactReduceBindingPartials) writeonly buffer Partials {
  vec4 partials[];
};

layout(std430, binding = kContactReduceBindingHeld) readonly buffer Held {
  ContactCount held[];
};
layout(std430, binding = kContactReduceBindingGripForce) readonly buffer GripForce {
  vec4 grip_force[];
};

#include "tool_contact_sum.glsl"
#include "grip_reduce.glsl"

// Row `row`'s partials: 2 tools of p.capacity each (force, then range), as tool_contact's.
uint partials_base(uint row) {
  return 2u * row * p.tools * p.capacity;
}

// The partial of candidates 64 k .. 64 k + 63 of row `row`, tool `tool`, as tool_contact's
// workgroup k writes it. A candidate that the force pass did not visit (fixed or removed since
// the broad phase) takes nothing, as tool_contact's `takes`.
void row_partial(uint row, uint tool, uint k) {
  const uint t = gl_LocalInvocationIndex;
  const uint stride = p.capacity * PHYXEL_WORKGROUP_SIZE;
  const uint slot = k * PHYXEL_WORKGROUP_SIZE + t;
  vec4 felt = vec4(0.0);
  vec2 range = vec2(kNoContactAxial, -kNoContactAxial);
  if (slot < count.total && (flags[list[slot]] & (kFlagFixed | kFlagRemoved)) == 0u) {
    felt = contact_force[(2u * row * p.tools + tool) * stride + slot];
    range = contact_force[((2u * row + 1u) * p.tools + tool) * stride + slot].xy;
  }
  sum_workgroup(felt, range);
  if (t != 0u) return;
  const uint base = partials_base(row);
  partials[base + tool * p.capacity + k] = wg_felt[0];
  partials[base + (p.tools + tool) * p.capacity + k] = vec4(wg_along[0], 0.0, 0.0);
}

void main() {
  const uint g = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (p.rows == 0u && p.sums == kContactReduceGripRow) {
    if (g != 0u) return;
    const vec4 sum = grip_sum(p.grasp, p.grip_capacity);
    if (gl_LocalInvocationIndex == 0u) samples[2u * (p.substep * p.tools + p.grasp)] = sum;
    return;
  }
  if (p.rows == 0u) {
    if (g >= p.tools) return;
    write_tool_sample(g, p.tools, p.capacity, p.substep, count.total);
    if (g == p.grasp) grip_reduce(g, p.tools, p.grip_capacity, p.substep);
    return;
  }
  if (p.sums == 0u) {  // one workgroup per partial slot; those past the candidates write none
    const uint pair = g / p.capacity, k = g % p.capacity;
    const uint used = (count.total + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
    if (pair >= p.rows * p.tools || k >= used) return;  // whole workgroups, before any barrier
    row_partial(p.substep + pair / p.tools, pair % p.tools, k);
    return;
  }
  if (g >= p.rows * p.tools) return;
  const uint row = p.substep + g / p.tools, tool = g % p.tools;
  write_partials_sample(partials_base(row), tool, p.tools, p.capacity, row, count.total);
  if (tool == p.grasp) grip_subtract(grip_force[2u * (row * p.tools + tool)], tool, p.tools, row);
}
