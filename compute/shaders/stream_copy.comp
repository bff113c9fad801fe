// dst[i] = src[i] for i < count (uvec4): each invocation copies per_thread elements `threads`
// apart, so consecutive invocations touch consecutive 16-byte words (coalesced) and several
// loads are in flight per invocation. The streaming roofline of compute/timing.h.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { StreamCopyPush p; };
layout(std430, binding = kStreamCopyBindingSrc) readonly buffer Src { uvec4 src[]; };
layout(std430, binding = kStreamCopyBindingDst) writeonly buffer Dst { uvec4 dst[]; };

void main() {
  const uint first = PHYXEL_GLOBAL_INDEX;
  if (first >= p.threads) return;
  for (uint k = 0; k < p.per_thread; ++k) {
    const uint i = first + k * p.threads;
    if (i < p.count) dst[i] = src[i];
  }
}
