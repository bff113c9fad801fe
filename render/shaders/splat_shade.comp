// Pass 3 of 3, normalisation and deferred Phong shading, one invocation per frame pixel:
// colour = sum(c w) / sum(w), normal = normalize(sum(n w)); a key light above left of the
// camera and a head light, eye space. A pixel where no splat was accumulated but a tool was
// hit (tool_visibility.comp) shows the tool: polished steel, Phong with a sharp highlight and
// a reflected sky/floor gradient. The fraction of a pixel's weight from cut faces makes it wet
// (a sharper, brighter highlight). Writes the frame in its layout: one eye, both side by
// side, or the red/cyan anaglyph of the two. With an environment (render/environment_map.h,
// the paper's eqs 33-34) a pixel that nothing covers shows the cube at its ray's direction,
// and the mirror fraction of a pixel's weight (kAccumMirror) shows the cube at the reflected
// ray instead of the lit texture (the highlight stays). With a backdrop layer
// (kShadeBackdropBit) a pixel that no disc reached shows the layer's colour (the backdrop
// shaded by this pass once per view, SplatRenderer::set_backdrop) unless a tool is nearer.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"
#include "tool_common.glsl"
#include "environment.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ShadePush p; };
layout(std430, binding = kShadeBindingAccum) buffer Accum { int accum[]; };
layout(std430, binding = kShadeBindingFrame) writeonly buffer Frame { uint frame[]; };
layout(std430, binding = kShadeBindingDepth) readonly buffer Depth { uint depth[]; };
layout(std430, binding = kShadeBindingBackdropDepth) readonly buffer BackdropDepth {
  uint backdrop_depth[];
};
layout(std430, binding = kShadeBindingBackdrop) readonly buffer Backdrop { uint backdrop[]; };
layout(set = kShadeSetEnvironment, binding = 0) uniform sampler2D environment;

// The environment along eye-space direction `d` (level 0: the background is magnified).
vec3 environment_colour(vec3 d) {
  const vec3 cube = mat3(p.eye_to_environment) * d;
  return textureLod(environment, environment_st(cube, p.near.w), 0.0).rgb;
}

const vec3 kKeyLight = vec3(-0.3487, 0.4982, 0.7937);  // normalize(-0.35, 0.5, 0.8)
const float kAmbient = 0.2;
const float kKeyDiffuse = 0.5;
const float kHeadDiffuse = 0.35;
const float kSpecular = 0.25;
const float kShininess = 32.0;
// Cut tissue is wet: a brighter, tighter highlight (mixed in by the pixel's cut-face weight).
const float kWetSpecular = 0.55;
const float kWetShininess = 90.0;

// Steel: a dark, slightly blue grey base that mirrors a studio (eye space): a bright sky
// above a sharp horizon and a dark floor below, a soft box around the key light and a dimmer
// one to the right, which give a rod the bands of a polished instrument at any orientation;
// a sharp highlight of the key light and a streak of the head light.
const vec3 kSteel = vec3(0.30, 0.32, 0.36);
const vec3 kSky = vec3(0.95, 0.97, 1.0);
const vec3 kHorizonSky = vec3(0.70, 0.73, 0.78);
const vec3 kHorizonFloor = vec3(0.38, 0.38, 0.40);
const vec3 kFloor = vec3(0.24, 0.24, 0.26);
const vec3 kFillBox = vec3(0.7071, -0.1414, 0.6928);  // normalize(0.5, -0.1, 0.49)

vec3 shade_tool(vec3 n, vec3 view) {
  const float key = max(dot(n, kKeyLight), 0.0);
  const vec3 r = reflect(-view, n);
  const float key_spec = pow(max(dot(reflect(-kKeyLight, n), view), 0.0), 24.0);
  const float head_spec = pow(max(dot(n, view), 0.0), 8.0);
  const vec3 env = r.y >= 0.0 ? mix(kHorizonSky, kSky, smoothstep(0.0, 0.6, r.y))
                              : mix(kHorizonFloor, kFloor, smoothstep(0.0, 0.4, -r.y));
  const float boxes = 0.35 * smoothstep(0.55, 0.85, dot(r, kKeyLight)) +
                      0.20 * smoothstep(0.6, 0.9, dot(r, kFillBox));
  const vec3 colour = kSteel * (0.12 + 0.25 * key) + 0.55 * env +
                      vec3(boxes + 0.8 * key_spec + 0.35 * head_spec);
  return min(colour, vec3(1.0));
}

// Reads the pixel's accumulation (planar, render_layout.h) and zeroes what was not zero: a
// tool's hit here, every channel where a disc was drawn (w != 0; the others are only added
// with w). The next frame then finds the buffer clear. The channels that only add values
// >= 0 (colour x w, w, cut, mirror) are read unsigned: exact up to 2^32, not 2^31.
vec3 shade(uint eye, uint x, uint y) {
  const uint plane = p.frame.w;
  const uint base = eye * kAccumChannels * plane, pixel = y * p.frame.x + x;
#define AT(c) (base + accum_index(c, plane, pixel))
#define SUM(c) float(uint(accum[AT(c)]))
  const float w = SUM(kAccumWeight);
  const uint tool = uint(accum[AT(kAccumTool)]);
  if (tool != 0u) accum[AT(kAccumTool)] = 0;
  const bool has_environment = p.near.z > 0.0;
  if (!(w > 0.0) && (p.frame.z & kShadeBackdropBit) != 0u) {
    // The backdrop layer, unless a tool is nearer (its exact depth won the depth buffer).
    const uint b = eye * p.frame.w + y * p.frame.x + x;
    if (tool == 0u || depth[b] >= backdrop_depth[b]) return unpackUnorm4x8(backdrop[b]).rgb;
  }
  if (!(w > 0.0) && tool == 0u && !has_environment) return kBackground;
  const vec4 frustum = eye == 0 ? p.frustum0 : p.frustum1;
  const float near = eye == 0 ? p.near.x : p.near.y;
  const vec3 view = -normalize(pixel_ray(frustum, near, vec2(p.frame.xy), vec2(x, y)));
  if (!(w > 0.0) && tool == 0u) {
    // The cube through the eye's frustum without its stereo shift: both eyes see it alike
    // (zero parallax). At infinity its parallax would be the whole IPD at the focal distance,
    // far more than eyes fuse at the distances of surgery.
    const float centre = 0.5 * (frustum.x + frustum.y);
    const vec4 unshifted = vec4(frustum.xy - centre, frustum.zw);
    return environment_colour(normalize(pixel_ray(unshifted, near, vec2(p.frame.xy), vec2(x, y))));
  }
  if (!(w > 0.0)) return shade_tool(unpack_tool_normal(tool), view);
  const vec3 albedo = vec3(SUM(kAccumRed), SUM(kAccumGreen), SUM(kAccumBlue)) / w;
  const vec3 sum_n =
      vec3(accum[AT(kAccumNormalX)], accum[AT(kAccumNormalY)], accum[AT(kAccumNormalZ)]);
  const float cut_w = SUM(kAccumCut);
  const float mirror_w = SUM(kAccumMirror);
  for (uint c = 0; c < kAccumChannels; ++c)
    if (c != kAccumTool) accum[AT(c)] = 0;
#undef SUM
#undef AT
  const float len = length(sum_n);
  const vec3 n = len > 0.0 ? sum_n / len : view;
  const float key = max(dot(n, kKeyLight), 0.0);
  const float head = max(dot(n, view), 0.0);
  const float wet = clamp(cut_w / w, 0.0, 1.0);
  const float r_dot_v = max(dot(reflect(-kKeyLight, n), view), 0.0);
  const float spec = mix(kSpecular * pow(r_dot_v, kShininess),
                         kWetSpecular * pow(r_dot_v, kWetShininess), wet);
  const vec3 lit = albedo * (kAmbient + kKeyDiffuse * key + kHeadDiffuse * head);
  const float mirror = has_environment ? clamp(mirror_w / w, 0.0, 1.0) : 0.0;
  const vec3 reflected = mirror > 0.0 ? environment_colour(reflect(-view, n)) : vec3(0.0);
  const vec3 colour = mix(lit, reflected, mirror) + spec;
  return min(colour, vec3(1.0));
}

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  const uint eye_width = p.frame.x, height = p.frame.y, layout_kind = p.frame.z & kShadeLayoutMask;
  const uint width = layout_kind == kShadeLayoutSideBySide ? 2 * eye_width : eye_width;
  if (i >= width * height) return;
  const uint y = i / width;
  const uint x = i - y * width;
  vec3 c;
  if (layout_kind == kShadeLayoutSideBySide) {
    const uint eye = x >= eye_width ? 1 : 0;
    c = shade(eye, x - eye * eye_width, y);
  } else if (layout_kind == kShadeLayoutAnaglyph) {
    c = vec3(shade(0, x, y).r, shade(1, x, y).gb);
  } else {
    c = shade(0, x, y);
  }
  frame[i] = packUnorm4x8(vec4(c, 1.0));
}
