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
// Included by splat_accumulate.comp (a 32-bit atomicAdd per channel) and, with
// PHYXEL_ACCUM_INT64, by splat_accumulate64.comp (one 64-bit atomicAdd per pair of channels,
// render_layout.h: the same ints while a low channel's sum stays below 2^32).
#ifndef PHYXEL_SPLAT_ACCUMULATE_GLSL
#define PHYXEL_SPLAT_ACCUMULATE_GLSL
#include "render_layout.h"
#include "splat_common.glsl"
#include "splat_raster.glsl"
#include "cut_tissue.glsl"
#include "torn_tissue.glsl"

layout(std430, binding = kRasterBindingDepth) readonly buffer Depth { uint depth[]; };
#ifdef PHYXEL_ACCUM_INT64
layout(std430, binding = kRasterBindingAccum) buffer Accum { uint64_t accum[]; };
#else
layout(std430, binding = kRasterBindingAccum) buffer Accum { int accum[]; };
#endif
layout(set = kRasterSetTexture, binding = 0) uniform sampler2D tissue;

// The texture coordinate where the ray along `dir` meets the splat's plane.
vec2 plane_st(EyeSplat s, vec3 dir) {
  const float dn = dot(dir, s.n);
  const vec3 d = (abs(dn) > 0.0 ? dot(s.c, s.n) / dn : 0.0) * dir - s.c;
  return vec2(s.ds.w + dot(s.ds.xyz, d), s.dt.w + dot(s.dt.xyz, d));
}

// Adds channels c (low, >= 0 in fixed point) and c + 1 of a pair; adds nothing for a zero:
// the sums are the same without the atomic.
void add(uint c, uint pixel, float low, float high) {
  const int lo = int(round(low * kAccumScale)), hi = int(round(high * kAccumScale));
#ifdef PHYXEL_ACCUM_INT64
  const uint plane = uint(accum.length()) / (kAccumChannels / 2);
  if ((lo | hi) != 0) atomicAdd(accum[(c >> 1) * plane + pixel], pack64(uvec2(lo, hi)));
#else
  const uint plane = uint(accum.length()) / kAccumChannels;
  if (lo != 0) atomicAdd(accum[accum_index(c, plane, pixel)], lo);
  if (hi != 0) atomicAdd(accum[accum_index(c + 1, plane, pixel)], hi);
#endif
}

// Adds channel c alone (a low one, its pair's high int untouched).
void add(uint c, uint pixel, float low) {
  const int lo = int(round(low * kAccumScale));
  if (lo == 0) return;
#ifdef PHYXEL_ACCUM_INT64
  const uint plane = uint(accum.length()) / (kAccumChannels / 2);
  atomicAdd(accum[(c >> 1) * plane + pixel], uint64_t(lo));
#else
  const uint plane = uint(accum.length()) / kAccumChannels;
  atomicAdd(accum[accum_index(c, plane, pixel)], lo);
#endif
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
  // Colours are >= 0 (texture, procedural tissues, baked colours): the low channels of pairs.
  colour = max(colour, vec3(0.0));
  add(kAccumRed, pixel, colour.r * w, n.x * w);
  add(kAccumGreen, pixel, colour.g * w, n.y * w);
  add(kAccumBlue, pixel, colour.b * w, n.z * w);
  add(kAccumWeight, pixel, w);
  if (s.cut || s.mirror > 0.0) add(kAccumCut, pixel, s.cut ? w : 0.0, s.mirror * w);
}

#endif  // PHYXEL_SPLAT_ACCUMULATE_GLSL
