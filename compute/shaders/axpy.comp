// y[i] = a * x[i] + y[i] for i < count.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { AxpyPush p; };
layout(std430, binding = kAxpyBindingX) readonly buffer X { float x[]; };
layout(std430, binding = kAxpyBindingY) buffer Y { float y[]; };

void main() {
  const uint i = PHYXEL_GLOBAL_INDEX;
  if (i >= p.count) return;
  y[i] = fma(p.a, x[i], y[i]);
}
