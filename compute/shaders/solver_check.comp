// result[0] = the smallest index of a phyxel whose u or v has a NaN or an infinity (set to
// 0xffffffff before). Tested on the bits (exponent all ones), which no fast-math setting of a
// driver can optimise away. Integer atomicMin: the result does not depend on the order.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { CheckPush p; };
layout(std430, binding = kCheckBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kCheckBindingVel) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = kCheckBindingResult) buffer Result { uint result[]; };

bool non_finite(vec3 x) {
  const uvec3 exponent = floatBitsToUint(x) & uvec3(0x7f800000u);
  return any(equal(exponent, uvec3(0x7f800000u)));
}

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.count) return;
  if (non_finite(disp[i].xyz) || non_finite(vel[i].xyz)) atomicMin(result[0], i);
}
