// Pass 3 of 3, normalisation and deferred Phong shading: colour = sum(c w) / sum(w), normal =
// normalize(sum(n w)); a key light above left of the camera and a head light, eye space.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"

layout(push_constant) uniform Push { EyePush eye; };
layout(input_attachment_index = 0, set = 0, binding = kShadeBindingColour) uniform subpassInput acc_colour;
layout(input_attachment_index = 1, set = 0, binding = kShadeBindingNormal) uniform subpassInput acc_normal;

layout(location = 0) out vec4 out_colour;

const vec3 kKeyLight = vec3(-0.3487, 0.4982, 0.7937);  // normalize(-0.35, 0.5, 0.8)
const float kAmbient = 0.2;
const float kKeyDiffuse = 0.5;
const float kHeadDiffuse = 0.35;
const float kSpecular = 0.25;
const float kShininess = 32.0;

void main() {
  const vec4 c = subpassLoad(acc_colour);
  if (!(c.a > 0.0)) {
    out_colour = vec4(kBackground, 1.0);
    return;
  }
  const vec3 albedo = c.rgb / c.a;
  const vec3 view = -normalize(pixel_ray(eye, gl_FragCoord.xy));
  const vec3 sum_n = subpassLoad(acc_normal).xyz;
  const float len = length(sum_n);
  const vec3 n = len > 0.0 ? sum_n / len : view;
  const float key = max(dot(n, kKeyLight), 0.0);
  const float head = max(dot(n, view), 0.0);
  const float spec = pow(max(dot(reflect(-kKeyLight, n), view), 0.0), kShininess);
  const vec3 colour = albedo * (kAmbient + kKeyDiffuse * key + kHeadDiffuse * head) + kSpecular * spec;
  out_colour = vec4(min(colour, vec3(1.0)), 1.0);
}
