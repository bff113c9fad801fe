// Cutting after a substep's contacts (SeverPush in layout.h; the CPU twin is
// CpuSolver::apply_cuts in engine/solver/cpu_solver_cutting.cpp): each candidate tests its live
// pairs against the quad each cutting blade swept, in the canonical order (lower index first)
// with the tie rule of engine/solver/cutting.cpp (an endpoint on the plane is on the positive
// side; a segment through an edge crosses, except through the front), and the pairs its edge
// holds (blade_edge.glsl), except those that would cut a phyxel from the side its blade keeps it
// on (sides_allow). Positions relative to the motion table's origin.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { SeverPush p; };
layout(std430, binding = kSeverBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kSeverBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kSeverBindingDisp) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kSeverBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kSeverBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kSeverBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kSeverBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kSeverBindingWeightHi
#define PHYXEL_PAIR_ACCESS 2
#include "pair_buffers.glsl"
layout(std430, binding = kSeverBindingFlags) buffer Flags { uint flags[]; };
layout(std430, binding = kSeverBindingQuads) readonly buffer Quads { CutQuad quads[]; };
layout(std430, binding = kSeverBindingSamples) readonly buffer Samples { vec4 samples[]; };
layout(std430, binding = kSeverBindingDirty) buffer Dirty { uint dirty[]; };
layout(std430, binding = kSeverBindingLog) buffer Log { uvec4 cut_log[]; };
layout(std430, binding = kSeverBindingCount) readonly buffer Count { ContactCount count; };
layout(std430, binding = kSeverBindingSides) buffer Sides { uint sides[]; };

const float kCutTieTolerance = 1e-6;  // m, engine/solver/cutting.h

// segment_crosses_triangle of engine/solver/cutting.cpp, in float.
bool crosses_triangle(vec3 p, vec3 q, vec3 a, vec3 b, vec3 c, out float t) {
  t = 0.0;
  const vec3 pa = p - a, qa = q - a, ba = b - a, ca = c - a;
  const vec3 n = cross(ba, ca);
  const float sp = dot(n, pa), sq = dot(n, qa);
  if ((sp >= 0.0) == (sq >= 0.0)) return false;
  const vec3 d = qa - pa;
  const vec3 ap = -pa, bp = ba - pa, cp = ca - pa;
  const float s1 = dot(d, cross(ap, bp));
  const float s2 = dot(d, cross(bp, cp));
  const float s3 = dot(d, cross(cp, ap));
  const bool inside = (s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) || (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0);
  if (inside) t = sp / (sp - sq);
  return inside;
}

// blade_severs of engine/solver/cutting.cpp: the quad a b c d crossed, but not within the tie
// tolerance of its front a -> d (the line the blade's tip swept).
bool severs_quad(vec3 p, vec3 q, vec3 a, vec3 b, vec3 c, vec3 d, out float t) {
  if (!crosses_triangle(p, q, a, b, c, t) && !crosses_triangle(p, q, a, c, d, t)) return false;
  const vec3 x = p - a + t * (q - p), front = d - a;
  const float len2 = dot(front, front);
  const float s = len2 > 0.0 ? clamp(dot(x, front) / len2, 0.0, 1.0) : 0.0;
  return length(x - s * front) >= kCutTieTolerance;
}

bool crosses_quad(vec3 p, vec3 q, CutQuad c, out float t) {
  return severs_quad(p, q, c.p0.xyz, c.p1.xyz, c.p2.xyz, c.p3.xyz, t);
}

// The blade body's strip (CpuSolver's body_strip): the blade's plane within the body's radius
// (p0.w) of the blade at the end pose, whose tip and end lie p3.w and p2.w along the edge from
// p3 and p2. A pair crossing it passes through the body.
bool crosses_body(vec3 p, vec3 q, CutQuad c, out float t) {
  t = 0.0;
  const float radius = c.p0.w;
  if (radius <= 0.0) return false;
  const vec3 e = c.edge.xyz;
  const vec3 tip = c.p3.xyz + c.p3.w * e, end = c.p2.xyz + c.p2.w * e;
  return severs_quad(p, q, tip - radius * e, end - radius * e, end + radius * e, tip + radius * e, t);
}

#include "blade_edge.glsl"

// The quad, the body's strip, or a pair the edge holds (tool_resist).
bool crosses_blade(vec3 p, vec3 q, CutQuad c, out float t) {
  if (crosses_quad(p, q, c, t) || crosses_body(p, q, c, t)) return true;
  float behind;
  float direction;
  return c.resist.x > 0.0 && edge_holds(p, q, edge_frame(c), t, behind, direction);
}

#include "pair_edit.glsl"

void main() {
  const uint slot = PHYXEL_GLOBAL_INDEX;
  if (slot >= count.total) return;
  const uint i = list[slot];
  const vec3 xi = rest[i].xyz - p.origin.xyz + disp[i].xyz;
  for (uint tool = 0u; tool < p.tools; ++tool) {
    const CutQuad quad = quads[p.row * p.tools + tool];
    const float threshold = quad.edge.w;
    if (threshold < 0.0) continue;  // no blade
    const vec3 felt = samples[2u * (p.sample_row * p.tools + tool)].xyz;  // tool_contact_reduce
    // cut_force of engine/solver/cutting.cpp: the edge pressed in, or the point (a stab).
    const vec3 axis = normalize(quad.p1.xyz - quad.p0.xyz);
    const bool cuts = max(0.0, max(-dot(felt, quad.edge.xyz), dot(felt, axis))) >= threshold;
    // The side the blade keeps i on (blade_edge.glsl): renewed by i alone, every substep.
    const bool sided = threshold > 0.0;  // blades with a threshold only (CpuSolver's)
    const uint side_i = sided ? side_at_start(sides[tool * p.phyxels + i], p.pass) : kSideNone;
    const vec3 normal = normalize(cross(quad.axis.xyz, quad.edge.xyz));
    uint cut_to = kSideNone;
    for (uint k = offset[i]; cuts && k < offset[i + 1u]; ++k) {
      if (!sided && pair_weight_bits(k) == 0u) continue;
      const uint j = nbr_index(k);
      const vec3 xj = rest[j].xyz - p.origin.xyz + disp[j].xyz;
      float t;
      const bool crosses = i < j ? crosses_blade(xi, xj, quad, t) : crosses_blade(xj, xi, quad, t);
      if (!crosses ||
          (sided && !sides_allow(side_i, side_at_start(sides[tool * p.phyxels + j], p.pass),
                                 normal, xi, xj)))
        continue;
      cut_to |= side_from(normal, xi, xj);  // severed now or before: no race on the weights
      if (pair_weight_bits(k) == 0u) continue;
      const uint lo = min(i, j), hi = max(i, j);
      const uint lo_slot = i < j ? k : find_slot(j, i);
      if (sever_pair_weight(lo_slot) == 0u) continue;  // another thread has it
      const uint hi_slot = i < j ? find_slot(j, i) : k;
      clear_pair_weight(hi_slot);
      mark_dirty(lo);
      mark_dirty(hi);
      const uint at = atomicAdd(cut_log[0].x, 1u);
      if (at < p.log_capacity) cut_log[1u + at] = uvec4(lo, hi, floatBitsToUint(t), 0u);
    }
    if (sided) sides[tool * p.phyxels + i] = side_entry(p.pass, side_i, side_after(side_i, cut_to));
  }
}
