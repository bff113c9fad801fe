// The SCNI band's force, one invocation per phyxel k that a band box lists (layout_band.h):
//   band_ext_k = ext_k - sum over its entries (b, c) of S_b c,
// which the force pass then starts from (CpuSolver: external + band_force, then the pairs).
// The twin of CpuSolver::band_force (engine/solver/cpu_solver_band.cpp), in the same order.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "layout_band.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { BandPush p; };
layout(std430, binding = kBandForceBindingNodes) readonly buffer Nodes { uvec4 nodes[]; };
layout(std430, binding = kBandForceBindingEntries) readonly buffer Entries { uvec2 entries[]; };
layout(std430, binding = kBandForceBindingCoeff) readonly buffer Coeff { vec4 coeff[]; };
layout(std430, binding = kBandForceBindingStress) readonly buffer Stress { vec4 box_stress[]; };
layout(std430, binding = kBandForceBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kBandForceBindingBandExt) writeonly buffer BandExt { vec4 band_ext[]; };

void main() {
  const uint n = PHYXEL_GLOBAL_INDEX;
  if (n >= p.count) return;
  const uvec4 node = nodes[n];
  vec3 f = vec3(0.0);
  for (uint e = node.y; e < node.z; ++e) {
    const uvec2 entry = entries[e];
    const uint b = 3u * entry.x;
    const mat3 s = mat3(box_stress[b].xyz, box_stress[b + 1u].xyz, box_stress[b + 2u].xyz);
    f -= s * coeff[entry.y].xyz;
  }
  const vec4 x = ext[node.x];
  band_ext[node.x] = vec4(x.xyz + f, x.w);
}
