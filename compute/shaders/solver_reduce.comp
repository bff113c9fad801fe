// out[g] = the sum of in[g * kScanBlock .. (g + 1) * kScanBlock), in a fixed order (each thread
// adds PHYXEL_SCAN_PER_THREAD consecutive elements, then a fixed tree over the workgroup), so
// the result does not depend on scheduling: energies() is deterministic.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ReducePush p; };
layout(std430, binding = kReduceBindingIn) readonly buffer Src { vec4 src[]; };
layout(std430, binding = kReduceBindingOut) writeonly buffer Dst { vec4 dst[]; };

shared vec4 partial[PHYXEL_WORKGROUP_SIZE];

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (group * kScanBlock >= p.count) return;  // whole workgroups only, before any barrier
  const uint t = gl_LocalInvocationID.x;
  const uint base = group * kScanBlock + t * PHYXEL_SCAN_PER_THREAD;
  vec4 sum = vec4(0.0);
  for (uint k = 0u; k < PHYXEL_SCAN_PER_THREAD; ++k) {
    if (base + k < p.count) sum += src[base + k];
  }
  partial[t] = sum;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) partial[t] += partial[t + half_size];
    barrier();
  }
  if (t == 0u) dst[group] = partial[0];
}
