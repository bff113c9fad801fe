// The largest |u| and |v| over all phyxels (the contact broad phase's reach, contact_reach in
// engine/solver/contact.h), one level of a reduction by kScanBlock: level 0 reads u and v,
// later levels the partials of the one before. A maximum does not depend on the order.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { MaxNormPush p; };
layout(std430, binding = kMaxNormBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kMaxNormBindingVel) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = kMaxNormBindingSrc) readonly buffer Src { vec4 src[]; };
layout(std430, binding = kMaxNormBindingOut) writeonly buffer Dst { vec4 dst[]; };

shared vec2 partial[PHYXEL_WORKGROUP_SIZE];

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (group * kScanBlock >= p.count) return;  // whole workgroups only, before any barrier
  const uint t = gl_LocalInvocationID.x;
  const uint base = group * kScanBlock + t * PHYXEL_SCAN_PER_THREAD;
  vec2 m = vec2(0.0);
  for (uint k = 0u; k < PHYXEL_SCAN_PER_THREAD; ++k) {
    const uint e = base + k;
    if (e >= p.count) break;
    const vec2 x = p.level == 0u ? vec2(length(disp[e].xyz), length(vel[e].xyz)) : src[e].xy;
    m = max(m, x);
  }
  partial[t] = m;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) partial[t] = max(partial[t], partial[t + half_size]);
    barrier();
  }
  if (t == 0u) dst[group] = vec4(partial[0], 0.0, 0.0);
}
