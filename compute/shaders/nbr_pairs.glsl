// The body of nbr_pairs.comp and nbr_pairs_f64.comp (which set PHYXEL_NBR_FLOAT64).
// Neighbour search, steps 4 and 6: every phyxel visits the 27 cells around its own and keeps
// the phyxels of those cells (same object, not itself) inside the support, by the CPU's rule
// (engine/solver/neighbours.cpp; see within_support in solver_nbr.glsl). kNbrCount writes how many;
// kNbrFill (after the counts were scanned into offset) writes them from offset[i], sorts the
// row by index and stores each pair's poly6 weight, aligned with the index.
#ifndef PHYXEL_NBR_PAIRS_GLSL
#define PHYXEL_NBR_PAIRS_GLSL
#include "solver_mls.glsl"
#include "solver_nbr.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { NbrPush p; };
layout(std430, binding = kNbrPairsBindingLocal) readonly buffer Local { vec4 local_pos[]; };
layout(std430, binding = kNbrPairsBindingRestLo) readonly buffer RestLo { vec4 rest_lo[]; };
layout(std430, binding = kNbrPairsBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kNbrPairsBindingClasses) readonly buffer Classes {
  SolverClass classes[];
};
layout(std430, binding = kNbrPairsBindingCellOf) readonly buffer CellOf { ivec4 cell_of[]; };
layout(std430, binding = kNbrPairsBindingBucketStart) readonly buffer Start {
  uint bucket_start[];
};
layout(std430, binding = kNbrPairsBindingSorted) readonly buffer Sorted { uint sorted_ids[]; };
layout(std430, binding = kNbrPairsBindingCount) buffer Count { uint pair_count[]; };
layout(std430, binding = kNbrPairsBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kNbrPairsBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kNbrPairsBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kNbrPairsBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kNbrPairsBindingWeightHi
#define PHYXEL_PAIR_ACCESS 1
#include "pair_buffers.glsl"

void main() {
  const uint i = p.first + PHYXEL_GLOBAL_INDEX;
  if (i >= p.end) return;
  const ivec4 ci = cell_of[i];
  if (ci.w < 0) {
    if (p.mode == kNbrCount) pair_count[i] = 0u;
    return;
  }
  const SolverClass cls = classes[flags[i] >> kFlagClassShift];
  const vec3 hi_i = local_pos[i].xyz;
  const vec3 lo_i = rest_lo[i].xyz;
  const uint row = p.mode == kNbrFill ? offset[i] : 0u;
  uint n = 0u;
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const ivec4 visit = ivec4(ci.xyz + ivec3(dx, dy, dz), ci.w);
        const uint b = cell_bucket(visit.xyz, uint(ci.w), p.bucket_mask);
        const uint end = bucket_start[b + 1u];
        for (uint s = bucket_start[b]; s < end; ++s) {
          const uint j = sorted_ids[s];
          if (j == i || cell_of[j] != visit) continue;
          if (!within_support(hi_i, lo_i, local_pos[j].xyz, rest_lo[j].xyz, cls.search))
            continue;
          if (p.mode == kNbrFill) set_nbr_index(row + n, j);
          ++n;
        }
      }
    }
  }
  if (p.mode == kNbrCount) {
    pair_count[i] = n;
    return;
  }
  // Insertion sort of the row (a few dozen entries), then the weights in row order.
  for (uint a = 1u; a < n; ++a) {
    const uint key = nbr_index(row + a);
    uint b = a;
    while (b > 0u && nbr_index(row + b - 1u) > key) {
      set_nbr_index(row + b, nbr_index(row + b - 1u));
      --b;
    }
    set_nbr_index(row + b, key);
  }
  for (uint a = 0u; a < n; ++a) {
    const vec3 x = local_pos[nbr_index(row + a)].xyz - hi_i;
    set_pair_weight(row + a, poly6_weight(dot(x, x), cls.kernel));
  }
}

#endif  // PHYXEL_NBR_PAIRS_GLSL
