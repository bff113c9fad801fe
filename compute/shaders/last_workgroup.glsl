// Whether this workgroup is the last of its dispatch to get here (tool_contact's fused
// reduction, tool_grasp's hold then reduce, the dirty list's precompute of tool_sever and
// solver_force_tear): each counts itself in the buffer variable `done`
// (declared coherent before this include) after its own writes; the last one sees every other
// workgroup's writes and sets `done` to 0 for the next dispatch. Call from every invocation.
#ifndef PHYXEL_LAST_WORKGROUP_GLSL
#define PHYXEL_LAST_WORKGROUP_GLSL

shared bool wg_last;

bool finished_last() {
  memoryBarrierBuffer();  // this workgroup's writes before its count
  barrier();
  if (gl_LocalInvocationIndex == 0u) {
    wg_last = atomicAdd(done, 1u) == gl_NumWorkGroups.x * gl_NumWorkGroups.y - 1u;
    if (wg_last) done = 0u;
  }
  barrier();
  memoryBarrierBuffer();
  return wg_last;
}

#endif  // PHYXEL_LAST_WORKGROUP_GLSL
