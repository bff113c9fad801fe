// Neighbour search, step 3 (after the bucket counts were scanned into bucket_start): every
// phyxel writes its index at its bucket's start plus its slot.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#define PHYXEL_NBR_FLOAT64 0
#include "solver_nbr.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { NbrPush p; };
layout(std430, binding = kNbrScatterBindingCellOf) readonly buffer CellOf { ivec4 cell_of[]; };
layout(std430, binding = kNbrScatterBindingSlot) readonly buffer Slot { uint slot[]; };
layout(std430, binding = kNbrScatterBindingBucketStart) readonly buffer Start {
  uint bucket_start[];
};
layout(std430, binding = kNbrScatterBindingSorted) writeonly buffer Sorted { uint sorted_ids[]; };

void main() {
  const uint i = p.first + PHYXEL_GLOBAL_INDEX;
  if (i >= p.end) return;
  const ivec4 c = cell_of[i];
  if (c.w < 0) return;
  sorted_ids[bucket_start[cell_bucket(c.xyz, uint(c.w), p.bucket_mask)] + slot[i]] = i;
}
