// Pass 1 of 3, visibility: the depth of the nearest disc, pushed back along the viewing ray by
// epsilon (in splat radii), so that pass 2 blends every disc within epsilon of the surface.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"

layout(push_constant) uniform Push { EyePush eye; };

layout(location = 0) flat in vec4 v_centre;
layout(location = 1) flat in vec4 v_normal;

void main() {
  const vec3 dir = pixel_ray(eye, gl_FragCoord.xy);
  const DiscHit h = intersect_disc(eye, dir, v_centre.xyz, v_centre.w, v_normal.xyz);
  if (!h.hit) discard;
  const vec3 behind = h.point + (eye.depth.z * v_centre.w) * normalize(dir);
  gl_FragDepth = min(linear_depth(eye, behind), 1.0);
}
