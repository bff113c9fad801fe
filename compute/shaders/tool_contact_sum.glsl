// One tool's contact sample of one substep from tool_contact's per-workgroup partials, by a
// whole workgroup in a fixed order (no float atomics: the samples are the same bits on every
// run): thread t sums the partials of workgroups t, t + workgroup, ... in order, then a fixed
// tree. The sample is the force on the tool (minus the sum of the forces on the phyxels) and the
// number of contacts (exact in float below 2^24), then in a second row the range the contacts
// span along the tool's axis (min, max; engine ToolContactSample::axial_min/max). Shared by
// tool_contact_reduce and tool_contact's fused reduction; include after the buffers
// contact_force and samples.
#ifndef PHYXEL_TOOL_CONTACT_SUM_GLSL
#define PHYXEL_TOOL_CONTACT_SUM_GLSL

shared vec4 sum_force[PHYXEL_WORKGROUP_SIZE];
shared vec2 sum_range[PHYXEL_WORKGROUP_SIZE];

void write_tool_sample(uint tool, uint tools, uint capacity, uint substep, uint candidates) {
  const uint t = gl_LocalInvocationIndex;
  vec4 sum = vec4(0.0);
  vec2 along = vec2(kNoContactAxial, -kNoContactAxial);
  const uint partials = (candidates + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
  for (uint k = t; k < partials; k += PHYXEL_WORKGROUP_SIZE) {
    sum += contact_force[tool * capacity + k];
    const vec2 s = contact_force[(tools + tool) * capacity + k].xy;
    along = vec2(min(along.x, s.x), max(along.y, s.y));
  }
  sum_force[t] = sum;
  sum_range[t] = along;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) {
      sum_force[t] += sum_force[t + half_size];
      sum_range[t] = vec2(min(sum_range[t].x, sum_range[t + half_size].x),
                          max(sum_range[t].y, sum_range[t + half_size].y));
    }
    barrier();
  }
  if (t == 0u) {
    const uint row = 2u * (substep * tools + tool);
    samples[row] = vec4(-sum_force[0].xyz, sum_force[0].w);
    samples[row + 1u] = vec4(sum_range[0], 0.0, 0.0);
  }
  barrier();  // a next tool reuses the arrays
}

#endif  // PHYXEL_TOOL_CONTACT_SUM_GLSL
