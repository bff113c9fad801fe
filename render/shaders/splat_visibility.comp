// Pass 1 of 3, visibility: per pixel, the linear depth of the nearest disc pushed back along
// the viewing ray by epsilon (in splat radii), so that pass 2 blends every disc within
// epsilon of the visible surface. atomicMin on the float's bits (depths are >= 0, where the
// bit patterns order as the values).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"
#include "splat_raster.glsl"

layout(std430, binding = kRasterBindingDepth) buffer Depth { uint depth[]; };

void splat_pixel(EyeSplat s, uint x, uint y) {
  const float near = p.depth.x, far = p.depth.y;
  const vec3 dir = eye_ray(x, y);
  const DiscHit h = intersect_disc(dir, s.c, s.r, s.n, near, far);
  if (!h.hit) return;
  const vec3 behind = h.point + (p.depth.z * s.r) * normalize(dir);
  const float d = min(linear_depth(near, far, behind), 1.0);
  atomicMin(depth[y * p.target.x + x], floatBitsToUint(d));
}
