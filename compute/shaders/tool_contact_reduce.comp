// The contact forces of one substep per tool, in a fixed order (no float atomics: the samples
// are the same bits on every run): one workgroup per tool; thread t sums the partials of
// tool_contact's workgroups t, t + workgroup, ... in order, then a fixed tree over the
// workgroup. The sample is the force on the tool (minus the sum of the forces on the phyxels)
// and the number of contacts (exact in float below 2^24), then in a second row the range the
// contacts span along the tool's axis (min, max; engine ToolContactSample::axial_min/max).
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

shared vec4 partial[PHYXEL_WORKGROUP_SIZE];
shared vec2 range[PHYXEL_WORKGROUP_SIZE];

void main() {
  const uint tool = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (tool >= p.tools) return;  // whole workgroups only, before any barrier
  const uint t = gl_LocalInvocationID.x;
  vec4 sum = vec4(0.0);
  vec2 along = vec2(kNoContactAxial, -kNoContactAxial);
  // One partial per workgroup of tool_contact (its candidates' sums).
  const uint partials = (count.total + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
  for (uint k = t; k < partials; k += PHYXEL_WORKGROUP_SIZE) {
    sum += contact_force[tool * p.capacity + k];
    const vec2 s = contact_force[(p.tools + tool) * p.capacity + k].xy;
    along = vec2(min(along.x, s.x), max(along.y, s.y));
  }
  partial[t] = sum;
  range[t] = along;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) {
      partial[t] += partial[t + half_size];
      range[t] = vec2(min(range[t].x, range[t + half_size].x),
                      max(range[t].y, range[t + half_size].y));
    }
    barrier();
  }
  if (t == 0u) {
    const uint row = 2u * (p.substep * p.tools + tool);
    samples[row] = vec4(-partial[0].xyz, partial[0].w);
    samples[row + 1u] = vec4(range[0], 0.0, 0.0);
  }
}
