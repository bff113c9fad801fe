// One object's kinetic energy and largest speed (the run loop's rest, sleep and runaway checks,
// GpuSolver::object_motion), one level of a reduction by kScanBlock: level 0 reads v and the
// mass of the object's phyxels, later levels the partials of the one before. The sums are
// added in a fixed order (each thread its PHYXEL_SCAN_PER_THREAD consecutive elements, then a
// fixed tree), so reruns give the same bits.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { MotionPush p; };
layout(std430, binding = kMotionBindingVel) readonly buffer Vel { vec4 vel[]; };
layout(std430, binding = kMotionBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kMotionBindingSrc) readonly buffer Src { vec4 src[]; };
layout(std430, binding = kMotionBindingOut) writeonly buffer Dst { vec4 dst[]; };

shared vec2 partial[PHYXEL_WORKGROUP_SIZE];

// A non-finite velocity makes its object's largest speed NaN, for the checks to see. Tested
// and kept on the bits (as solver_check does): a driver's fast math may drop a NaN from a
// comparison, max() or isnan().
bool nan_bits(float a) {
  return (floatBitsToUint(a) & 0x7fffffffu) > 0x7f800000u;
}

bool non_finite(vec3 x) {
  const uvec3 exponent = floatBitsToUint(x) & uvec3(0x7f800000u);
  return any(equal(exponent, uvec3(0x7f800000u)));
}

float largest(float a, float b) {
  return nan_bits(a) ? a : (nan_bits(b) ? b : max(a, b));
}

void main() {
  const uint group = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
  if (group * kScanBlock >= p.count) return;  // whole workgroups only, before any barrier
  const uint t = gl_LocalInvocationID.x;
  const uint base = group * kScanBlock + t * PHYXEL_SCAN_PER_THREAD;
  vec2 m = vec2(0.0);  // (kinetic energy, largest speed)
  for (uint k = 0u; k < PHYXEL_SCAN_PER_THREAD; ++k) {
    const uint e = base + k;
    if (e >= p.count) break;
    vec2 x;
    if (p.level == 0u) {
      const vec3 v = vel[p.first + e].xyz;
      const float v2 = dot(v, v);
      const float speed = non_finite(v) ? uintBitsToFloat(0x7fc00000u) : sqrt(v2);  // NaN
      x = vec2(0.5 * ext[p.first + e].w * v2, speed);
    } else {
      x = src[e].xy;
    }
    m = vec2(m.x + x.x, largest(m.y, x.y));
  }
  partial[t] = m;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) {
      const vec2 a = partial[t], b = partial[t + half_size];
      partial[t] = vec2(a.x + b.x, largest(a.y, b.y));
    }
    barrier();
  }
  if (t == 0u) dst[p.slot + group] = vec4(partial[0], 0.0, 0.0);
}
