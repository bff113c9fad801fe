// The contact forces of one substep per tool (tool_contact_sum.glsl), one workgroup per tool:
// where tool_resist adds to tool_contact's partials between the two (tool_contact sums them
// itself otherwise, kContactFuseReduce).
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

#include "tool_contact_sum.glsl"

void main() {
  const uint tool = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (tool >= p.tools) return;  // whole workgroups only, before any barrier
  write_tool_sample(tool, p.tools, p.capacity, p.substep, count.total);
}
