// What the passes that sever pairs share (tool_sever, solver_tear): the slot of a pair in the
// CSR, a phyxel put in the dirty list once (kFlagCutDirty; dirty[0] the count, then the
// phyxels), and the precompute of that list by the pass's last workgroup. Include after the
// buffers offset, flags, dirty, cut_log, done and those of solver_precompute.glsl, the push
// constant p (log_capacity), and pair_buffers.glsl.
#include "last_workgroup.glsl"
#include "solver_precompute.glsl"

// The slot of `target` in the sorted row of phyxel `row`.
uint find_slot(uint row, uint target) {
  uint lo = offset[row], hi = offset[row + 1u];
  while (lo < hi) {
    const uint mid = (lo + hi) / 2u;
    if (nbr_index(mid) < target) lo = mid + 1u; else hi = mid;
  }
  return lo;
}

void mark_dirty(uint x) {
  const uint before = atomicOr(flags[x], kFlagCutDirty | kFlagPairsEdited);
  if ((before & kFlagCutDirty) != 0u) return;
  dirty[1u + atomicAdd(dirty[0], 1u)] = x;
}

// Appends (lo, hi, t, torn) to the cut log (past p.log_capacity the count alone grows).
void log_severed(uint lo, uint hi, float t, uint torn) {
  const uint at = atomicAdd(cut_log[0].x, 1u);
  if (at < p.log_capacity) cut_log[1u + at] = uvec4(lo, hi, floatBitsToUint(t), torn);
}

// Call from every invocation after its pass's work: the workgroup that finishes last reruns
// the precompute of the phyxels in the dirty list (none most substeps: no dependent dispatch).
void precompute_dirty_list() {
  if (!finished_last()) return;
  const uint dirtied = dirty[0];
  for (uint e = gl_LocalInvocationIndex; e < dirtied; e += gl_WorkGroupSize.x)
    precompute_phyxel(dirty[1u + e], true);
}
