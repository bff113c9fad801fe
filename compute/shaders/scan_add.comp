// Exclusive prefix sum, second half: adds the scanned block totals to every element.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ScanPush p; };
layout(std430, binding = kScanAddBindingOut) buffer Dst { uint dst[]; };
layout(std430, binding = kScanAddBindingSums) readonly buffer Sums { uint block_prefix[]; };

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.count) return;
  dst[i] += block_prefix[i / kScanBlock];
}
