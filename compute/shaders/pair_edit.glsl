// What the passes that sever pairs share (tool_sever, solver_tear): the slot of a pair in the
// CSR, and a phyxel put in the dirty list once (kFlagCutDirty) for the precompute that the
// pass's last workgroup runs. Include after the buffers offset, flags and dirty and
// pair_buffers.glsl.
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
  const uint at = atomicAdd(dirty[0], 1u);
  dirty[4u + at] = x;
}
