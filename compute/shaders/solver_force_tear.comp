// The force pass (solver_force.glsl) with the tear test fused after it, one dispatch a substep
// while tearing (ForceTearPush in layout.h; the CPU twin is CpuSolver::apply_tears in
// engine/solver/cpu_solver_tearing.cpp, which follows the forces as here, the criterion
// engine/solver/tearing.h). The list is the force list, then the stress pass's phyxels not in
// it (p.tear_only of them: the tear test alone). Each phyxel tests its live pairs to higher
// indices, from its row's end (the rows ascend) down to its own index, p.lanes invocations per
// phyxel taking every p.lanes-th pair (no pair's test reads another's outcome: the same pairs
// tear in any order and with any lanes); a pair whose mean normal stress reaches the mean of the
// two strengths is severed, logged (i, j, 0.5, torn) and both phyxels go to the dirty list. A
// phyxel left without a fit (kFlagNoFit, set by a precompute before this pass) severs every pair
// it still has to a phyxel that tears, lower indices too, but for those to a lower such phyxel
// (that one's); the stress test leaves pairs to such a phyxel alone. So each pair has one
// phyxel that decides it, and that one clears its own slot only, after its force read the row:
// the force of every phyxel in this pass is that of the intact pairs, as on the CPU. The other
// slot (a row another invocation may be reading) is cleared by the workgroup that finishes last,
// which then reruns the precompute of the dirty list (none most substeps).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#define PHYXEL_FORCE_TEARS 1
#include "solver_force.glsl"

layout(std430, binding = kForceTearBindingPrincipal) readonly buffer Principal {
  float principal[];
};
layout(std430, binding = kForceTearBindingCauchy) readonly buffer Cauchy { vec4 cauchy[]; };
// Coherent: the last workgroup reads the flags, weights and list that the others wrote.
layout(std430, binding = kForceTearBindingDirty) coherent buffer Dirty { uint dirty[]; };
layout(std430, binding = kForceTearBindingLog) buffer Log { uvec4 cut_log[]; };
layout(std430, binding = kForceTearBindingAinv) writeonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kForceTearBindingResid) writeonly buffer Resid { vec4 resid[]; };
layout(std430, binding = kForceTearBindingDone) coherent buffer Done { uint done; };

#include "pair_edit.glsl"

// pair_tear_threshold of engine/solver/tearing.h.
float pair_threshold(float ti, float tj) {
  const bool holds_i = ti > 0.0 && !isinf(ti);
  const bool holds_j = tj > 0.0 && !isinf(tj);
  return holds_i && holds_j ? 0.5 * (ti + tj) : 0.0;
}

mat3 tensor(uint i) {
  const vec4 a = cauchy[2u * i], b = cauchy[2u * i + 1u];
  return mat3(a.x, a.w, b.x, a.w, a.y, b.y, b.x, b.y, a.z);
}

float strength(uint x) {
  return classes[flags[x] >> kFlagClassShift].search.w;
}

// Severs pair slot k of row i (to j) on i's side: the dirty list and the log (i < j first).
// j's slot follows in the last workgroup (mend_partners).
void tear(uint i, uint k, uint j) {
  clear_pair_weight(k);
  mark_dirty(i);
  log_severed(min(i, j), max(i, j), 0.5, 1u);
}

// A phyxel left without a fit: every live pair of row i (strength ti) to a phyxel that tears.
void tear_unfit(uint i, float ti, uint lane) {
  for (uint k = offset[i] + lane; k < offset[i + 1u]; k += p.lanes) {
    if (pair_weight_bits(k) == 0u) continue;
    const uint j = nbr_index(k);
    if (j < i && (flags[j] & kFlagNoFit) != 0u) continue;  // j's
    if (pair_threshold(ti, strength(j)) > 0.0) tear(i, k, j);
  }
}

void tear_pairs(uint invocation) {
  const uint slot = invocation / p.lanes;
  const uint lane = invocation % p.lanes;
  if (slot >= p.count + p.tear_only) return;
  const uint i = pass_list[slot];
  const float ti = strength(i);
  if (!(ti > 0.0)) return;
  if ((flags[i] & kFlagNoFit) != 0u) {
    tear_unfit(i, ti, lane);
    return;
  }
  const vec3 xi = rest[i].xyz + disp_in[i].xyz;
  const float pi = principal[i];
  bool loaded = false;
  mat3 si = mat3(0.0);
  // Below this sum of principal stresses no pair of i reaches its threshold, whatever j's class
  // (0.9998 < 0.9999 keeps the skip inside the test below after float rounding): j's flags and
  // class are loaded only for pairs that may tear.
  const float no_tear_below = 0.9998 * (ti + p.weakest);
  const uint begin = offset[i], end = offset[i + 1u];
  for (uint back = lane; back < end - begin; back += p.lanes) {
    const uint k = end - 1u - back;
    const uint j = nbr_index(k);
    if (j <= i) break;  // and every pair before it
    if (pi + principal[j] < no_tear_below || pair_weight_bits(k) == 0u) continue;
    if ((flags[j] & kFlagNoFit) != 0u) continue;  // j tears it (tear_unfit)
    const float threshold = pair_threshold(ti, strength(j));
    if (!(threshold > 0.0)) continue;
    if (0.5 * (pi + principal[j]) < 0.9999 * threshold) continue;  // s_ij cannot reach it
    if (!loaded) {
      si = tensor(i);
      loaded = true;
    }
    const vec3 r = rest[j].xyz + disp_in[j].xyz - xi;
    const float len2 = dot(r, r);
    if (!(len2 > 0.0)) continue;
    const float s_ij = dot(r, (0.5 * (si + tensor(j))) * r) / len2;
    if (!(s_ij >= threshold)) continue;
    tear(i, k, j);
  }
}

shared uint deciders;

// In the last workgroup: the other slot of each pair torn here (a decider's zero slot whose
// partner's is live: the rows were symmetric before the pass), its phyxel into the dirty list;
// then the precompute of the list.
void mend_partners() {
  if (!finished_last()) return;
  if (gl_LocalInvocationIndex == 0u) deciders = dirty[0];
  barrier();
  const uint marked = deciders;  // the partners join the list after them
  for (uint e = gl_LocalInvocationIndex; e < marked; e += gl_WorkGroupSize.x) {
    const uint x = dirty[1u + e];
    for (uint k = offset[x]; k < offset[x + 1u]; ++k) {
      if (pair_weight_bits(k) != 0u) continue;
      const uint j = nbr_index(k);
      const uint back = find_slot(j, x);
      if (pair_weight_bits(back) == 0u) continue;
      clear_pair_weight(back);
      mark_dirty(j);
    }
  }
  memoryBarrierBuffer();
  barrier();
  precompute_listed();
  // With the contact fused (kForceContactDirtyReset), the list's empty header that
  // tool_contact would have written after this pass.
  if ((p.contact_fuse & kForceContactDirtyReset) == 0u) return;
  barrier();  // every invocation read the count
  if (gl_LocalInvocationIndex == 0u) dirty[0] = 0u;
}

void main() {
  const uint invocation = PHYXEL_GLOBAL_INDEX;
  force_pass(invocation);
  tear_pairs(invocation);
  mend_partners();
}
