// The reduction of a grasper's grip forces into its sample, shared by tool_grasp,
// tool_contact's last workgroup and tool_contact_reduce (the same bits). Include after the
// buffers held, grip_force and samples.
#ifndef PHYXEL_GRIP_REDUCE_GLSL
#define PHYXEL_GRIP_REDUCE_GLSL

shared vec4 grip_partial[PHYXEL_WORKGROUP_SIZE];

// By a whole workgroup: the tool's grip forces summed in a fixed order (tool_contact_reduce's),
// subtracted from its sample of the substep, and the held count into the second row's z.
void grip_reduce(uint tool, uint tools, uint capacity, uint substep) {
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
  if (t == 0u) {
    const uint row = 2u * (substep * tools + tool);
    samples[row].xyz -= grip_partial[0].xyz;
    samples[row + 1u].z = grip_partial[0].w;
  }
}

#endif  // PHYXEL_GRIP_REDUCE_GLSL
