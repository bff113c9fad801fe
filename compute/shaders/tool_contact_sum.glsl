// One tool's contact sample of one substep from tool_contact's per-workgroup partials, by a
// whole workgroup in a fixed order (no float atomics: the samples are the same bits on every
// run): thread t sums the partials of workgroups t, t + workgroup, ... in order, then a fixed
// tree. The sample is the force on the tool (minus the sum of the forces on the phyxels) and the
// number of contacts (exact in float below 2^24), then in a second row the range the contacts
// span along the tool's axis (min, max; engine ToolContactSample::axial_min/max). Shared by
// tool_contact_reduce and tool_contact's fused reduction (sum_workgroup: tool_contact's
// per-workgroup partial, also tool_contact_reduce's over solver_force_tear's rows); include
// after the buffers contact_force and samples.
#ifndef PHYXEL_TOOL_CONTACT_SUM_GLSL
#define PHYXEL_TOOL_CONTACT_SUM_GLSL

shared vec4 wg_felt[PHYXEL_WORKGROUP_SIZE];
shared vec2 wg_along[PHYXEL_WORKGROUP_SIZE];

// One workgroup's partial of one tool over its 64 candidates' felt and along (a fixed tree in
// shared memory): into wg_felt[0] and wg_along[0]. Every invocation calls it; a barrier must
// follow the reads of the result before the next call.
void sum_workgroup(vec4 felt, vec2 along) {
  const uint lane = gl_LocalInvocationIndex;
  wg_felt[lane] = felt;
  wg_along[lane] = along;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (lane < half_size) {
      wg_felt[lane] += wg_felt[lane + half_size];
      wg_along[lane] = vec2(min(wg_along[lane].x, wg_along[lane + half_size].x),
                            max(wg_along[lane].y, wg_along[lane + half_size].y));
    }
    barrier();
  }
}

// The sample from each thread's ordered sum of partials (sum, along): the same fixed tree.
void write_sample(vec4 sum, vec2 along, uint tool, uint tools, uint substep) {
  sum_workgroup(sum, along);
  if (gl_LocalInvocationIndex == 0u) {
    const uint row = 2u * (substep * tools + tool);
    samples[row] = vec4(-wg_felt[0].xyz, wg_felt[0].w);
    samples[row + 1u] = vec4(wg_along[0], 0.0, 0.0);
  }
  barrier();  // a next tool reuses the arrays
}

// The partials of tool_contact's workgroups from contact_force[base], as tool_contact lays
// them out (force per tool, then range per tool; `capacity` apart).
void write_partials_sample(uint base, uint tool, uint tools, uint capacity, uint substep,
                           uint candidates) {
  const uint t = gl_LocalInvocationIndex;
  vec4 sum = vec4(0.0);
  vec2 along = vec2(kNoContactAxial, -kNoContactAxial);
  const uint partials = (candidates + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
  for (uint k = t; k < partials; k += PHYXEL_WORKGROUP_SIZE) {
    sum += contact_force[base + tool * capacity + k];
    const vec2 s = contact_force[base + (tools + tool) * capacity + k].xy;
    along = vec2(min(along.x, s.x), max(along.y, s.y));
  }
  write_sample(sum, along, tool, tools, substep);
}

void write_tool_sample(uint tool, uint tools, uint capacity, uint substep, uint candidates) {
  write_partials_sample(0u, tool, tools, capacity, substep, candidates);
}

#endif  // PHYXEL_TOOL_CONTACT_SUM_GLSL
