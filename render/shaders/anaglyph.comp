// Red/cyan anaglyph from a side-by-side frame: red from the left half, green and blue from
// the right half (both RGBA8, one uint per pixel, rows top to bottom).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { AnaglyphPush p; };
layout(std430, binding = kAnaglyphBindingStereo) readonly buffer Stereo { uint stereo[]; };
layout(std430, binding = kAnaglyphBindingOut) writeonly buffer Out { uint pixels[]; };

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.width * p.height) return;
  const uint y = i / p.width;
  const uint x = i - y * p.width;
  const uint left = stereo[y * 2u * p.width + x];
  const uint right = stereo[y * 2u * p.width + p.width + x];
  pixels[i] = (left & 0x000000ffu) | (right & 0x00ffff00u) | 0xff000000u;
}
