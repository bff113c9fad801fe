// Pass 2 of 3, attribute accumulation: every disc no farther than the visible depth + epsilon
// adds colour x weight, weight and normal x weight (additive blending into two RGBA16F
// targets). The texture coordinate varies across the disc with the splat's texture gradient.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"

layout(push_constant) uniform Push { EyePush eye; };
layout(set = 0, binding = kSplatBindingTexture) uniform sampler2D tissue;

layout(location = 0) flat in vec4 v_centre;
layout(location = 1) flat in vec4 v_normal;
layout(location = 2) flat in vec4 v_ds;
layout(location = 3) flat in vec4 v_dt;

layout(location = 0) out vec4 out_colour;  // rgb: colour x weight, a: weight
layout(location = 1) out vec4 out_normal;  // xyz: normal x weight

void main() {
  const vec3 dir = pixel_ray(eye, gl_FragCoord.xy);
  const DiscHit h = intersect_disc(eye, dir, v_centre.xyz, v_centre.w, v_normal.xyz);
  const vec3 d = h.point - v_centre.xyz;
  const vec2 st = vec2(v_ds.w + dot(v_ds.xyz, d), v_dt.w + dot(v_dt.xyz, d));
  // Derivatives before any fragment of the quad is discarded.
  const vec2 st_dx = dFdx(st);
  const vec2 st_dy = dFdy(st);
  if (!h.hit) discard;
  gl_FragDepth = linear_depth(eye, h.point);
  // A truncated Gaussian: weight 1 at the centre, exp(-2) at the rim.
  const float w = exp(-2.0 * h.q2);
  const vec3 colour = textureGrad(tissue, st, st_dx, st_dy).rgb;
  // Two-sided: the normal that faces the eye (cut or thin tissue shows its back).
  const vec3 n = dot(v_normal.xyz, dir) > 0.0 ? -v_normal.xyz : v_normal.xyz;
  out_colour = vec4(colour * w, w);
  out_normal = vec4(n * w, 0.0);
}
