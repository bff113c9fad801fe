// What the passes that sever pairs share (tool_sever, solver_force_tear): the slot of a pair in the
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

// Per phyxel of a short dirty list, up to this many lanes load its pairs.
const uint kDirtyMaxLanes = 32u;

shared vec4 staged_pair[gl_WorkGroupSize.x];  // x_j - x_i, the stored weight
shared uint staged_removed[gl_WorkGroupSize.x];
shared uint staged_longest;  // the longest row of the list

// A list of at most half the workgroup's size in one round: `lanes` lanes per phyxel load its
// pairs `lanes` at a time, and the first adds them in the row's order (precompute_phyxel's
// sums: the same bits, without a pair's loads at a time on one lane).
void precompute_short_list(uint dirtied, uint lanes) {
  const uint t = gl_LocalInvocationIndex;
  const uint q = t % lanes;
  const bool in_list = t / lanes < dirtied;
  const uint i = in_list ? dirty[1u + t / lanes] : 0u;
  const uint first = in_list ? offset[i] : 0u, end = in_list ? offset[i + 1u] : 0u;
  const vec3 xi = in_list ? local_pos[i].xyz : vec3(0.0);
  const uint fl = in_list ? flags[i] : 0u;
  const SolverClass cls = classes[fl >> kFlagClassShift];
  if (t == 0u) staged_longest = 0u;
  barrier();
  if (in_list && q == 0u) atomicMax(staged_longest, end - first);
  barrier();
  const uint longest = staged_longest;
  PairMoments m = PairMoments(mat3(0.0), mat3(0.0), false);
  for (uint base = 0u; base < longest; base += lanes) {
    const uint k = first + base + q;
    if (k < end) {
      const uint j = nbr_index(k);
      staged_pair[t] = vec4(local_pos[j].xyz - xi, pair_weight(k));
      staged_removed[t] = flags[j] & kFlagRemoved;
    }
    barrier();
    if (in_list && q == 0u)
      for (uint r = 0u; r < lanes && first + base + r < end; ++r)
        add_pair_moment(m, staged_pair[t + r].xyz, staged_pair[t + r].w,
                        staged_removed[t + r] != 0u, cls.kernel);
    barrier();
  }
  if (in_list && q == 0u) finish_precompute(i, fl, cls, m, true);
}

// The precompute of the phyxels in the dirty list, by the calling workgroup (the last to
// finish): a short list with several lanes per phyxel.
void precompute_listed() {
  const uint dirtied = dirty[0];
  if (dirtied == 0u) return;
  uint lanes = 1u;
  while (lanes < kDirtyMaxLanes && dirtied * lanes * 2u <= gl_WorkGroupSize.x) lanes *= 2u;
  if (lanes > 1u) {
    precompute_short_list(dirtied, lanes);
    return;
  }
  for (uint e = gl_LocalInvocationIndex; e < dirtied; e += gl_WorkGroupSize.x)
    precompute_phyxel(dirty[1u + e], true);
}
