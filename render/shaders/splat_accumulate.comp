// Pass 2 of 3, attribute accumulation: every disc no farther than the visible depth (which
// includes epsilon) adds colour x w, w and normal x w to its pixel, w a truncated Gaussian of
// the distance from the disc's centre. The texture coordinate varies across the disc with the
// splat's texture gradient; the texture's level of detail comes from its change to the next
// pixel right and down (on the disc's plane), as a fragment shader's derivatives would.
// Cut faces (kSplatCutFace) take the procedural cut tissue of cut_tissue.glsl at their own
// (s, t) instead of the texture, and add w to the cut channel (kAccumCut) as well. Torn faces
// (kSplatTornFace) take the torn tissue of torn_tissue.glsl instead, and its bumped normal.
// Backdrop discs (kSplatBaked) take the colour baked into them (render/backdrop.h).
// Mirror surfaces add mirror x w to kAccumMirror (the shading pass reflects the environment
// there).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"
#include "splat_raster.glsl"
#include "cut_tissue.glsl"
#include "torn_tissue.glsl"

layout(std430, binding = kRasterBindingDepth) readonly buffer Depth { uint depth[]; };
layout(std430, binding = kRasterBindingAccum) buffer Accum { int accum[]; };
layout(set = kRasterSetTexture, binding = 0) uniform sampler2D tissue;

// The texture coordinate where the ray along `dir` meets the splat's plane.
vec2 plane_st(EyeSplat s, vec3 dir) {
  const float dn = dot(dir, s.n);
  const vec3 d = (abs(dn) > 0.0 ? dot(s.c, s.n) / dn : 0.0) * dir - s.c;
  return vec2(s.ds.w + dot(s.ds.xyz, d), s.dt.w + dot(s.dt.xyz, d));
}

// Adds nothing for a zero: the sums are the same without the atomic.
void add(uint at, float value) {
  const int v = int(round(value * kAccumScale));
  if (v != 0) atomicAdd(accum[at], v);
}

void splat_pixel(EyeSplat s, uint x, uint y) {
  const float near = p.depth.x, far = p.depth.y;
  const vec3 dir = eye_ray(x, y);
  const DiscHit h = intersect_disc(dir, s.c, s.r, s.n, near, far);
  if (!h.hit) return;
  const uint pixel = y * p.target.x + x;
  if (h.depth > uintBitsToFloat(depth[pixel])) return;
  // A truncated Gaussian: weight 1 at the centre, exp(-2) at the rim.
  const float w = exp(-2.0 * h.q2);
  // Branches, not ternaries: a ternary of calls may evaluate both sides (llvmpipe does), and
  // the procedural tissues are far dearer than the texture. A backdrop disc's colour was
  // baked on the CPU: nothing to evaluate here.
  vec3 colour;
  vec3 n_splat = s.n;
  if (s.baked) {
    colour = s.ds.xyz;
  } else {
    const vec3 d = h.point - s.c;
    const vec2 st = vec2(s.ds.w + dot(s.ds.xyz, d), s.dt.w + dot(s.dt.xyz, d));
    const vec3 step_x = vec3((p.frustum.y - p.frustum.x) / float(p.target.x), 0.0, 0.0);
    const vec3 step_y = vec3(0.0, (p.frustum.z - p.frustum.w) / float(p.target.y), 0.0);
    const vec2 st_dx = plane_st(s, dir + step_x) - st;
    const vec2 st_dy = plane_st(s, dir + step_y) - st;
    if (s.torn) {
      colour = torn_tissue(st, st_dx, st_dy);
      n_splat = torn_normal(s.n, s.ds.xyz, s.dt.xyz, st, st_dx, st_dy);
    } else if (s.cut) {
      colour = cut_tissue(st, st_dx, st_dy);
    } else {
      colour = textureGrad(tissue, st, st_dx, st_dy).rgb;
    }
  }
  // Two-sided: the normal that faces the eye (cut or thin tissue shows its back).
  const vec3 n = dot(s.n, dir) > 0.0 ? -n_splat : n_splat;
  const uint plane = uint(accum.length()) / kAccumChannels;  // planar (render_layout.h)
  add(pixel, colour.r * w);
  add(pixel + plane, colour.g * w);
  add(pixel + 2 * plane, colour.b * w);
  add(pixel + 3 * plane, w);
  add(pixel + 4 * plane, n.x * w);
  add(pixel + 5 * plane, n.y * w);
  add(pixel + 6 * plane, n.z * w);
  if (s.cut) add(pixel + kAccumCut * plane, w);
  if (s.mirror > 0.0) add(pixel + kAccumMirror * plane, s.mirror * w);
}
