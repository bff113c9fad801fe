// The edge's resistance after a substep's contacts (ResistPush in layout.h; the CPU twin is
// CpuSolver::apply_edge_resistance in engine/solver/cpu_solver_cutting.cpp): each candidate
// sums, per blade, the forces stiffness * a_ij * behind of the pairs the edge pushes (canonical
// order, its share (1 - t) or t), a_ij = (V_i + V_j) / (S_i + S_j) (pair_area_share), bounds
// the sum by the threshold (bounded_edge_push), adds
// dt / m times them to its velocity, and each workgroup adds its sums to tool_contact's partials
// (tool_contact_reduce turns them into the force on the tool; with kContactFuseReduce this
// dispatch's last workgroup does, in the same order: the same bits, one dispatch and barrier
// less per substep). A pair that would cut a phyxel from the side its blade keeps it on is not
// held (blade_edge.glsl, sides_allow). Reads positions, writes only its own velocity: no atomics.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ResistPush p; };
layout(std430, binding = kResistBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kResistBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kResistBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kResistBindingVel) buffer Vel { vec4 vel[]; };
layout(std430, binding = kResistBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kResistBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kResistBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kResistBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kResistBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kResistBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kResistBindingWeightHi
#define PHYXEL_PAIR_ACCESS 0
#include "pair_buffers.glsl"
layout(std430, binding = kResistBindingQuads) readonly buffer Quads { CutQuad quads[]; };
layout(std430, binding = kResistBindingForce) coherent buffer Force { vec4 contact_force[]; };
layout(std430, binding = kResistBindingCount) readonly buffer Count { ContactCount count; };
layout(std430, binding = kResistBindingSamples) writeonly buffer Samples { vec4 samples[]; };
layout(std430, binding = kResistBindingDone) coherent buffer Done { uint done; };
layout(std430, binding = kResistBindingDirty) writeonly buffer Dirty { uint dirty[]; };
layout(std430, binding = kResistBindingSides) readonly buffer Sides { uint sides[]; };

#include "last_workgroup.glsl"
#include "tool_contact_sum.glsl"

#include "blade_edge.glsl"

shared vec3 wg_force[PHYXEL_WORKGROUP_SIZE];

vec3 position(uint i) {
  return rest[i].xyz - p.origin.xyz + disp[i].xyz;
}

// S_i of pair_area_share: half the sum over i's neighbours of |(x_k - x_i) . n|.
float plane_crossings(uint i, vec3 n) {
  const vec3 xi = position(i);
  float sum = 0.0;
  for (uint k = offset[i]; k < offset[i + 1u]; ++k) sum += abs(dot(n, position(nbr_index(k)) - xi));
  return 0.5 * sum;
}

// Phyxel x's (at position at) kept side for the tool, lapsed where stale (side_near_plane).
uint side_of(uint tool, uint x, EdgeFrame f, vec3 at) {
  return side_near_plane(side_at_start(sides[tool * p.phyxels + x], p.pass),
                         sides[side_normal_index(tool, p.tools, p.phyxels, x)], f, at);
}

vec3 held_pairs_force(uint i, EdgeFrame f, uint tool) {
  const vec3 xi = position(i);
  const uint side_i = side_of(tool, i, f, xi);
  vec3 total = vec3(0.0);
  float s_i = -1.0;
  for (uint k = offset[i]; k < offset[i + 1u]; ++k) {
    if (pair_weight(k) == 0.0) continue;
    const uint j = nbr_index(k);
    const vec3 xj = position(j);
    float t;
    float behind;
    float direction;
    if (!(i < j ? edge_pushes(xi, xj, f, t, behind, direction)
                : edge_pushes(xj, xi, f, t, behind, direction)) ||
        !sides_allow(side_i, side_of(tool, j, f, xj), f.normal, xi, xj))
      continue;
    if (s_i < 0.0) s_i = plane_crossings(i, f.normal);
    const float s_j = plane_crossings(j, f.normal);
    const float sum = i < j ? s_i + s_j : s_j + s_i;
    const float area = sum > 0.0 ? (i < j ? rest[i].w + rest[j].w : rest[j].w + rest[i].w) / sum : 0.0;
    total += (f.stiffness * area * behind * (i < j ? 1.0 - t : t) * direction) * f.edge;
  }
  return total;
}

void main() {
  const uint slot = PHYXEL_GLOBAL_INDEX;
  const uint group = slot / PHYXEL_WORKGROUP_SIZE;
  const uint lane = gl_LocalInvocationIndex;
  const bool candidate = slot < count.total;  // no early return: barriers below
  const uint i = candidate ? list[slot] : 0u;
  const bool takes = candidate && (flags[i] & (kFlagFixed | kFlagRemoved)) == 0u;
  vec3 v = takes ? vel[i].xyz : vec3(0.0);
  bool moved = false;
  for (uint tool = 0u; tool < p.tools; ++tool) {
    const CutQuad quad = quads[p.row * p.tools + tool];
    vec3 force = vec3(0.0);
    if (takes && quad.edge.w >= 0.0 && quad.resist.x > 0.0) {
      force = held_pairs_force(i, edge_frame(quad), tool);
      // bounded_edge_push: at most the blade's threshold (quad.edge.w) on one phyxel.
      const float size = length(force);
      if (size > quad.edge.w) force *= quad.edge.w / size;
      if (force != vec3(0.0)) {
        v += p.dt / ext[i].w * force;
        moved = true;
      }
    }
    wg_force[lane] = force;
    barrier();
    for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
      if (lane < half_size) wg_force[lane] += wg_force[lane + half_size];
      barrier();
    }
    if (lane == 0u && group * PHYXEL_WORKGROUP_SIZE < count.total)
      contact_force[tool * p.capacity + group].xyz += wg_force[0];
    barrier();
  }
  if (moved) vel[i] = vec4(v, 0.0);
  // kContactFuseReduce: after every workgroup added its sums, the last one writes the samples.
  if ((p.fuse & kContactFuseReduce) == 0u || !finished_last()) return;
  for (uint t = 0u; t < p.tools; ++t)
    write_tool_sample(t, p.tools, p.capacity, p.substep, count.total);
  if (lane == 0u && (p.fuse & kContactFuseDirtyReset) != 0u) dirty[0] = 0u;  // nothing severed
}
