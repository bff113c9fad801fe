// dst[i] = base + i for i < count: every invocation writes its own global index. The tests use
// it to prove dispatch()'s group rounding (all elements written, none beyond).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { IotaPush p; };
layout(std430, binding = kIotaBindingDst) writeonly buffer Dst { uint dst[]; };

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.count) return;
  dst[i] = p.base + i;
}
