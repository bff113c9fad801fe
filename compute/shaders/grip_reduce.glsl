// The reduction of a grasper's grip forces into its sample, shared by tool_grasp,
// tool_contact's last workgroup and tool_contact_reduce (the same bits). Include after the
// buffers held, grip_force and samples.
#ifndef PHYXEL_GRIP_REDUCE_GLSL
#define PHYXEL_GRIP_REDUCE_GLSL

shared vec4 grip_partial[PHYXEL_WORKGROUP_SIZE];

// By a whole workgroup: the tool's grip forces summed in a fixed order (tool_contact_reduce's):
// their force and the held count (w), returned to every invocation.
vec4 grip_sum(uint tool, uint capacity) {
  const uint t = gl_LocalInvocationIndex;
  const uint region = tool * capacity;
  vec4 sum = vec4(0.0);
  for (uint k = t; k < held[tool].total; k += PHYXEL_WORKGROUP_SIZE)
    sum += grip_force[region + k];
  grip_partial[t] = sum;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) grip_partial[t] += grip_partial[t + half_size];
    barrier();
  }
  return grip_partial[0];
}

// The grip's sum `g` out of the tool's sample of the substep: its force subtracted, the held
// count into the second row's z (lane 0).
void grip_subtract(vec4 g, uint tool, uint tools, uint substep) {
  if (gl_LocalInvocationIndex != 0u) return;
  const uint row = 2u * (substep * tools + tool);
  samples[row].xyz -= g.xyz;
  samples[row + 1u].z = g.w;
}

// By a whole workgroup: grip_sum subtracted from the tool's sample of the substep.
void grip_reduce(uint tool, uint tools, uint capacity, uint substep) {
  grip_subtract(grip_sum(tool, capacity), tool, tools, substep);
}

#endif  // PHYXEL_GRIP_REDUCE_GLSL
