// A removal's edit of the flags and pair weights in place, and the flag counts after it
// (layout.h EditPush): no read-back of the flags or weights, no upload of all of them.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { EditPush p; };
layout(std430, binding = kEditBindingFlags) buffer Flags { uint flags[]; };
layout(std430, binding = kEditBindingEdits) readonly buffer Edits { uint edits[]; };
layout(std430, binding = kEditBindingSlots) readonly buffer Slots { uint slots[]; };
layout(std430, binding = kEditBindingCounts) buffer Counts { uint counts[]; };
#define PHYXEL_PAIR_INDEX_BINDING kEditBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kEditBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kEditBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kEditBindingWeightHi
#define PHYXEL_PAIR_ACCESS 2
#include "pair_buffers.glsl"

shared uint regularised[PHYXEL_WORKGROUP_SIZE];
shared uint edited[PHYXEL_WORKGROUP_SIZE];

void main() {
  const uint k = PHYXEL_GLOBAL_INDEX;
  if (p.mode == 0u) {
    if (k < p.count) atomicOr(flags[edits[2u * k]], edits[2u * k + 1u]);
    if (k < p.slots) clear_pair_weight(slots[k]);
    return;
  }
  const uint t = gl_LocalInvocationID.x;
  const uint f = k < p.count ? flags[k] : 0u;
  regularised[t] = (f & kFlagRegularised) != 0u ? 1u : 0u;
  edited[t] = (f & kFlagPairsEdited) != 0u ? 1u : 0u;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) {
      regularised[t] += regularised[t + half_size];
      edited[t] += edited[t + half_size];
    }
    barrier();
  }
  if (t == 0u) {
    if (regularised[0] > 0u) atomicAdd(counts[0], regularised[0]);
    if (edited[0] > 0u) atomicAdd(counts[1], edited[0]);
  }
}
