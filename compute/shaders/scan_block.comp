// Exclusive prefix sum, first half: each workgroup scans kScanBlock elements (each thread
// PHYXEL_SCAN_PER_THREAD consecutive ones, then a shared-memory scan over the threads) and
// writes its block total to block_sums. Integer sums: exact and order-independent.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ScanPush p; };
layout(std430, binding = kScanBindingIn) readonly buffer Src { uint src[]; };
layout(std430, binding = kScanBindingOut) writeonly buffer Dst { uint dst[]; };
layout(std430, binding = kScanBindingSums) writeonly buffer Sums { uint block_sums[]; };

shared uint partial[PHYXEL_WORKGROUP_SIZE];

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  // Whole workgroups beyond the data (from the y spill of large dispatches) leave together,
  // before any barrier.
  if (group * kScanBlock >= p.count) return;
  const uint t = gl_LocalInvocationID.x;
  const uint base = group * kScanBlock + t * PHYXEL_SCAN_PER_THREAD;
  uint v[PHYXEL_SCAN_PER_THREAD];
  uint sum = 0u;
  for (uint k = 0u; k < PHYXEL_SCAN_PER_THREAD; ++k) {
    v[k] = base + k < p.input_count ? src[base + k] : 0u;
    sum += v[k];
  }
  partial[t] = sum;
  barrier();
  for (uint step = 1u; step < PHYXEL_WORKGROUP_SIZE; step <<= 1u) {
    const uint add = t >= step ? partial[t - step] : 0u;
    barrier();
    partial[t] += add;
    barrier();
  }
  uint running = partial[t] - sum;
  for (uint k = 0u; k < PHYXEL_SCAN_PER_THREAD; ++k) {
    if (base + k < p.count) dst[base + k] = running;
    running += v[k];
  }
  if (t == PHYXEL_WORKGROUP_SIZE - 1u) block_sums[group] = partial[t];
}
