// The tool pass, before splat visibility, one invocation per pixel of one eye: every tool
// (tool_common.glsl) against the pixel's ray; the nearest entry between the near and far
// planes writes its exact linear depth into the visibility buffer with the splats' encoding
// (atomicMin on the float's bits) and its eye-space normal into the pixel's kAccumTool
// channel. The splats then draw over it where they are nearer (their depth + epsilon is
// the visible depth where they are in front, and splats behind the tool's depth are not
// accumulated); splat_shade.comp shows the tool where no splat was accumulated.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"
#include "tool_common.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ToolPush p; };
layout(std430, binding = kToolBindingTools) readonly buffer Tools { RenderTool tools[]; };
layout(std430, binding = kToolBindingDepth) buffer Depth { uint depth[]; };
layout(std430, binding = kToolBindingAccum) buffer Accum { int accum[]; };

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  const uint width = p.target.x, height = p.target.y;
  if (i >= width * height) return;
  const uint y = i / width;
  const uint x = i - y * width;
  const float near = p.depth.x, far = p.depth.y;
  const vec3 dir = normalize(pixel_ray(p.frustum, near, vec2(width, height), vec2(x, y)));
  const mat3 rot = mat3(p.view);
  float best_depth = 2.0;
  vec3 best_normal = vec3(0.0, 0.0, 1.0);
  for (uint k = 0; k < p.target.z; ++k) {
    const RenderTool tool = tools[k];
    const vec3 tip = (p.view * vec4(tool.tip.xyz, 1.0)).xyz;
    const vec3 axis = rot * tool.axis.xyz;
    // Most pixels' rays pass the tool's bounding ball (with a margin far above rounding):
    // they would miss every part of it, at a fraction of the cost.
    const vec3 mid = tip + (0.5 * tool.axis.w) * axis;
    const float reach = 1.001 * (0.5 * tool.axis.w + tool.tip.w);
    const vec3 off = mid - dot(dir, mid) * dir;
    if (dot(off, off) > reach * reach) continue;
    const ToolHit h = tool_entry(dir, tip, axis, tool.axis.w, tool.tip.w);
    if (h.t >= 1e30) continue;
    const float d = linear_depth(near, far, h.t * dir);
    if (d >= 0.0 && d <= 1.0 && d < best_depth) {
      best_depth = d;
      best_normal = h.normal;
    }
  }
  if (best_depth > 1.0) return;
  atomicMin(depth[i], floatBitsToUint(best_depth));
  accum[accum_index(kAccumTool, uint(accum.length()) / kAccumChannels, i)] =
      int(pack_tool_normal(best_normal));
}
