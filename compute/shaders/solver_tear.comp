// Tearing after a substep's force pass (TearPush in layout.h; the CPU twin is
// CpuSolver::apply_tears in engine/solver/cpu_solver_tearing.cpp, the criterion
// engine/solver/tearing.h): each phyxel of the stress pass tests its live pairs to higher
// indices, from its row's end (the rows ascend) down to its own index, p.lanes invocations per
// phyxel taking every p.lanes-th pair (no pair's test reads another's outcome: the same pairs
// tear in any order and with any lanes); a pair whose mean normal stress reaches the mean of the
// two strengths is severed on both sides, logged (i, j, 0.5, torn) and both phyxels go to the
// dirty list. A phyxel left without a fit (kFlagNoFit, set by a precompute before this pass)
// severs every pair it still has to a phyxel that tears, lower indices too, but for those to a
// lower such phyxel (that one's); the stress test leaves pairs to such a phyxel alone. Then the
// workgroup that finishes last reruns the precompute of the phyxels in the dirty list (none most
// substeps: no dependent dispatch).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { TearPush p; };
layout(std430, binding = kTearBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kTearBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kTearBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kTearBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kTearBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kTearBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kTearBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kTearBindingWeightHi
#define PHYXEL_PAIR_ACCESS 2
#define PHYXEL_PAIR_WEIGHT_COHERENT
#include "pair_buffers.glsl"
// Coherent: the last workgroup reads the flags, weights and list that the others wrote.
layout(std430, binding = kTearBindingFlags) coherent buffer Flags { uint flags[]; };
layout(std430, binding = kTearBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kTearBindingPrincipal) readonly buffer Principal { float principal[]; };
layout(std430, binding = kTearBindingCauchy) readonly buffer Cauchy { vec4 cauchy[]; };
layout(std430, binding = kTearBindingDirty) coherent buffer Dirty { uint dirty[]; };
layout(std430, binding = kTearBindingLog) buffer Log { uvec4 cut_log[]; };
layout(std430, binding = kTearBindingLocal) buffer Local { vec4 local_pos[]; };
layout(std430, binding = kTearBindingAinv) writeonly buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kTearBindingResid) writeonly buffer Resid { vec4 resid[]; };
layout(std430, binding = kTearBindingDone) coherent buffer Done { uint done; };

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

#include "pair_edit.glsl"

float strength(uint x) {
  return classes[flags[x] >> kFlagClassShift].search.w;
}

// Severs pair slot k of row i (to j): both sides, the dirty list and the log (i < j first).
void tear(uint i, uint k, uint j) {
  clear_pair_weight(k);
  clear_pair_weight(find_slot(j, i));
  mark_dirty(i);
  mark_dirty(j);
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
  if (slot >= p.count) return;
  const uint i = list[slot];
  const float ti = strength(i);
  if (!(ti > 0.0)) return;
  if ((flags[i] & kFlagNoFit) != 0u) {
    tear_unfit(i, ti, lane);
    return;
  }
  const vec3 xi = rest[i].xyz + disp[i].xyz;
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
    const vec3 r = rest[j].xyz + disp[j].xyz - xi;
    const float len2 = dot(r, r);
    if (!(len2 > 0.0)) continue;
    const float s_ij = dot(r, (0.5 * (si + tensor(j))) * r) / len2;
    if (!(s_ij >= threshold)) continue;
    tear(i, k, j);
  }
}

void main() {
  tear_pairs(PHYXEL_GLOBAL_INDEX);
  precompute_dirty_list();
}
