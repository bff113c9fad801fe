// Cutting after a substep's contacts (SeverPush in layout_surgery.h; the CPU twin is
// CpuSolver::apply_cuts in engine/solver/cpu_solver_cutting.cpp): SeverGroups.lanes invocations
// per candidate, each taking every lanes-th of its live pairs, test each pair against the quad
// each cutting blade swept, in the canonical order (lower index first) with the tie rule of
// engine/solver/cutting.cpp (an endpoint on the plane is on the positive side; a segment through
// an edge crosses, except through the front), and the pairs its edge holds (blade_edge.glsl);
// whatever the force, the pairs a blade's edge carries past its reach (edge_passes); a blade
// with a threshold severs none that would cut a phyxel from the side it keeps it on
// (sides_allow; each lane merges what it cut into the candidate's side entry with a
// compare-and-swap). Without sides a lane's first pair is loaded before the blades' setup. A
// pair goes to the first tool that takes it (the CPU's tool by tool: a later tool finds it
// severed); no pair's test reads another's outcome, so the same pairs are severed with the same
// t in any order. A pair is tested against a blade only where its segment meets the ball around
// all that blade can sever this substep (blade_ball). Then the workgroup that finishes last
// reruns the precompute of the phyxels put in the dirty list (none most substeps: no dependent
// dispatch; kSeverWorkgroupSize lanes, several per phyxel for a short list). Beside the stress
// pass (p.stress_epoch != 0: no barrier between them), it then waits for that pass's end (at
// most kSeverStressWaitSpins polls, else kCutLogStressMissed in the log) and redoes the stress
// of those phyxels (solver_stress.glsl, the same sums in the same order), which the pass may
// have computed from the pairs and precompute before the cut. Positions relative to the motion
// table's origin.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = kSeverWorkgroupSize) in;

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
#define PHYXEL_PAIR_WEIGHT_COHERENT
#include "pair_buffers.glsl"
// Coherent: the last workgroup reads the flags, weights and list that the others wrote.
layout(std430, binding = kSeverBindingFlags) coherent buffer Flags { uint flags[]; };
layout(std430, binding = kSeverBindingQuads) readonly buffer Quads { CutQuad quads[]; };
layout(std430, binding = kSeverBindingSamples) readonly buffer Samples { vec4 samples[]; };
layout(std430, binding = kSeverBindingDirty) coherent buffer Dirty { uint dirty[]; };
layout(std430, binding = kSeverBindingLog) buffer Log { uvec4 cut_log[]; };
layout(std430, binding = kSeverBindingCount) readonly buffer Count {
  ContactCount count;
  SeverGroups sever;  // tool_broad_scan's: the lanes per candidate
};
layout(std430, binding = kSeverBindingLocal) coherent buffer Local { vec4 local_pos[]; };
layout(std430, binding = kSeverBindingClasses) readonly buffer Classes { SolverClass classes[]; };
// Coherent: the redo of the stress beside the stress pass reads what the precompute wrote.
layout(std430, binding = kSeverBindingAinv) coherent buffer Ainv { vec4 ainv[]; };
layout(std430, binding = kSeverBindingResid) coherent buffer Resid { vec4 resid[]; };
layout(std430, binding = kSeverBindingDone) coherent buffer Done { uint done; };
layout(std430, binding = kSeverBindingSides) buffer Sides { uint sides[]; };
layout(std430, binding = kSeverBindingStress) coherent writeonly buffer Stress { vec4 stress[]; };
layout(std430, binding = kSeverBindingStressList) readonly buffer StressList {
  uint stress_list[];
};
layout(std430, binding = kSeverBindingStressDone) coherent buffer StressDone {
  uint stress_finished;  // solver_stress's workgroups written (p.stress_epoch: all of them)
};

const float kCutTieTolerance = 1e-6;  // m, engine/solver/cutting.h
// Whether a blade may keep sides (one with a threshold): GpuSolver picks the pipeline.
layout(constant_id = 2) const bool kSeverSided = true;

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

// Where the blade cuts in this substep: the quad, the body's strip, or a pair the edge holds
// (tool_resist); whatever its force: a pair its edge carries past its reach (edge_passes).
bool crosses_blade(vec3 p, vec3 q, CutQuad c, bool cuts, out float t) {
  t = 0.0;
  if (cuts && (crosses_quad(p, q, c, t) || crosses_body(p, q, c, t))) return true;
  if (!(c.resist.x > 0.0)) return false;
  const EdgeFrame f = edge_frame(c);
  float behind;
  float direction;
  if (cuts && edge_holds(p, q, f, t, behind, direction)) return true;
  return edge_passes(p, q, f, t);
}

#include "pair_edit.glsl"
#include "solver_stress.glsl"

// Whether the tool's blade cuts in this substep: its sample presses the edge in, or the point
// (a stab), with at least its threshold (cut_force of engine/solver/cutting.cpp), or it is in
// the cutting state (the previous pass cut, advanced and crossed a pair) and advances.
bool tool_cuts(CutQuad quad, uint tool) {
  const float threshold = quad.edge.w;
  if (threshold < 0.0) return false;  // no blade
  if (threshold == 0.0) return true;   // cut_force >= 0 always: the sample is not read
  const uint state = blade_state_index(tool, p.tools, p.phyxels, (p.pass - 1u) & 1u);
  if (quad.frame_edge.w > 0.0 && sides[state] == p.pass) return true;
  const vec3 felt = samples[2u * (p.sample_row * p.tools + tool)].xyz;  // tool_contact_reduce
  const vec3 axis = normalize(quad.p1.xyz - quad.p0.xyz);
  return max(0.0, max(-dot(felt, quad.edge.xyz), dot(felt, axis))) >= threshold;
}

// Per tool of the first kSeverBallTools, a ball holding everything its blade can sever this
// substep (the swept quad, the body's strip, the region the edge holds or carries past its
// reach: each the convex hull of corners in it), widened for float round-off: centre, radius
// squared; w < 0 where the blade severs nothing. A pair whose segment misses the ball is left
// untested (it cannot cross), so the same pairs are severed as when testing all of them.
// blade_cutting: whether its force reached the threshold (else only edge_passes severs).
const uint kSeverBallTools = 8u;
shared vec4 blade_ball[kSeverBallTools];
shared bool blade_cutting[kSeverBallTools];

void hold_in_ball(inout float r2, vec3 centre, vec3 x) {
  r2 = max(r2, dot(x - centre, x - centre));
}

// The corners of the region the edge holds or carries past its reach: tip + along axis + across
// edge, along in [0, span], |across . edge| <= front + depth + the faster end's motion
// (edge_holds' and edge_passes' bounds), in the axis-edge plane.
void hold_edge_region(inout float r2, vec3 centre, CutQuad c) {
  const EdgeFrame f = edge_frame(c);
  const float g = dot(f.axis, f.edge), det = 1.0 - g * g;
  if (!(det > 1e-6)) {
    r2 = 1e30;  // axis along the edge: no ball
    return;
  }
  const float across =
      abs(f.front) + abs(f.depth) + max(abs(f.tip_motion), abs(f.end_motion));
  for (uint corner = 0u; corner < 4u; ++corner) {
    const float along = (corner & 1u) != 0u ? f.span : 0.0;
    const float side = (corner & 2u) != 0u ? across : -across;
    // c . axis = along, c . edge = side, c in the plane of axis and edge.
    const float a = (along - g * side) / det, e = (side - g * along) / det;
    hold_in_ball(r2, centre, f.tip + a * f.axis + e * f.edge);
  }
}

// Whether the blade may sever anything this substep: it cuts, or its edge holds pairs.
bool tool_severs(CutQuad c, bool cuts) {
  return cuts || (c.edge.w >= 0.0 && c.resist.x > 0.0);
}

vec4 blade_ball_of(uint tool, bool cuts) {
  const CutQuad c = quads[p.row * p.tools + tool];
  if (!tool_severs(c, cuts)) return vec4(0.0, 0.0, 0.0, -1.0);
  const vec3 centre = 0.25 * (c.p0.xyz + c.p1.xyz + c.p2.xyz + c.p3.xyz);
  float r2 = 0.0;
  hold_in_ball(r2, centre, c.p0.xyz);
  hold_in_ball(r2, centre, c.p1.xyz);
  hold_in_ball(r2, centre, c.p2.xyz);
  hold_in_ball(r2, centre, c.p3.xyz);
  const float radius = c.p0.w;
  const vec3 e = c.edge.xyz;
  const vec3 tip = c.p3.xyz + c.p3.w * e, end = c.p2.xyz + c.p2.w * e;
  if (radius > 0.0)
    for (uint corner = 0u; corner < 4u; ++corner)
      hold_in_ball(
          r2, centre,
          ((corner & 1u) != 0u ? end : tip) + ((corner & 2u) != 0u ? radius : -radius) * e);
  if (c.resist.x > 0.0) hold_edge_region(r2, centre, c);
  const float r = sqrt(r2) * 1.01 + 1e-5;  // m: far above float round-off at these sizes
  return vec4(centre, r * r);
}

// Whether the segment a -> b comes within the ball s (centre, radius squared).
bool segment_meets_ball(vec3 a, vec3 b, vec4 s) {
  const vec3 d = b - a, w = s.xyz - a;
  const float dd = dot(d, d);
  const float u = dd > 0.0 ? clamp(dot(w, d) / dd, 0.0, 1.0) : 0.0;
  const vec3 x = w - u * d;
  return dot(x, x) <= s.w;
}

// Whether the tool's blade may sever the pair xi -> xj this substep (tools past
// kSeverBallTools: whether it severs at all).
bool blade_may_sever(uint tool, CutQuad quad, vec3 xi, vec3 xj) {
  if (tool >= kSeverBallTools) return tool_severs(quad, tool_cuts(quad, tool));
  const vec4 ball = blade_ball[tool];
  return ball.w >= 0.0 && segment_meets_ball(xi, xj, ball);
}

bool blade_cuts(uint tool, CutQuad quad) {
  return tool < kSeverBallTools ? blade_cutting[tool] : tool_cuts(quad, tool);
}

// Fills blade_ball and blade_cutting (every invocation calls it); whether any blade may sever
// this substep.
bool any_tool_severs() {
  const uint t = gl_LocalInvocationIndex;
  if (t < min(p.tools, kSeverBallTools)) {
    const bool cuts = tool_cuts(quads[p.row * p.tools + t], t);
    blade_cutting[t] = cuts;
    blade_ball[t] = blade_ball_of(t, cuts);
  }
  barrier();
  for (uint tool = 0u; tool < p.tools; ++tool) {
    const CutQuad quad = quads[p.row * p.tools + tool];
    if (tool < kSeverBallTools ? blade_ball[tool].w >= 0.0
                               : tool_severs(quad, tool_cuts(quad, tool)))
      return true;
  }
  return false;
}

// Phyxel x's (at position at) kept side for the tool, lapsed where stale (side_near_plane).
uint side_of(uint tool, CutQuad quad, uint x, vec3 at) {
  return side_near_plane(side_at_start(sides[tool * p.phyxels + x], p.pass),
                         sides[side_normal_index(tool, p.tools, p.phyxels, x)], edge_frame(quad),
                         at);
}

// Whether the tool's blade crosses pair (i, j) at t (whatever the sides): it may (its ball)
// and its quad, body strip or edge does.
bool blade_crosses(CutQuad quad, uint tool, vec3 xi, uint i, vec3 xj, uint j, out float t) {
  t = 0.0;
  if (!blade_may_sever(tool, quad, xi, xj)) return false;
  const bool cuts = blade_cuts(tool, quad);
  return i < j ? crosses_blade(xi, xj, quad, cuts, t) : crosses_blade(xj, xi, quad, cuts, t);
}

// Whether the sides a blade with a threshold (sided) keeps let it sever pair (i, j).
bool sides_let(CutQuad quad, uint tool, uint i, vec3 xi, uint j, vec3 xj) {
  if (!kSeverSided || !(quad.edge.w > 0.0)) return true;
  const vec3 normal = normalize(cross(quad.axis.xyz, quad.edge.xyz));
  return sides_allow(side_of(tool, quad, i, xi), side_of(tool, quad, j, xj), normal, xi, xj);
}

// Whether the tool's blade severs pair (i, j) at t: it crosses it and the sides let it.
bool blade_takes(CutQuad quad, uint tool, uint i, vec3 xi, uint j, vec3 xj, out float t) {
  return blade_crosses(quad, tool, xi, i, xj, j, t) && sides_let(quad, tool, i, xi, j, xj);
}

// Whether a tool before this one severs the pair in this substep (the CPU's tool by tool).
bool earlier_tool_takes(uint tool, uint i, vec3 xi, uint j, vec3 xj) {
  for (uint before = 0u; before < tool; ++before) {
    float t;
    if (blade_takes(quads[p.row * p.tools + before], before, i, xi, j, xj, t)) return true;
  }
  return false;
}

// Severs pair (i, j) (slot k of i) at t unless the invocation of its other side claimed it
// first (the atomic exchange of the lower index's slot).
void claim_pair(uint i, uint j, uint k, float t) {
  const uint lo = min(i, j), hi = max(i, j);
  const uint lo_slot = i < j ? k : find_slot(j, i);
  if (sever_pair_weight(lo_slot) == 0u) return;  // another invocation has it
  clear_pair_weight(i < j ? find_slot(j, i) : k);
  mark_dirty(lo);
  mark_dirty(hi);
  log_severed(lo, hi, t, 0u);
}

// Pair slot k of candidate i (at xi) against one tool: severed unless a tool before it takes
// it or the invocation of its other side claimed it first (the atomic exchange of the lower
// index's slot). Returns the side it cuts i to (kSideNone if the blade does not take it); a
// pair severed before counts, so the side does not depend on which invocation ran first.
// crossed: set where the blade crosses the pair, whatever the sides (it is in tissue).
uint sever_pair(uint tool, CutQuad quad, uint i, vec3 xi, uint k, inout bool crossed) {
  const bool sided = quad.edge.w > 0.0;
  if (!sided && pair_weight_bits(k) == 0u) return kSideNone;
  const uint j = nbr_index(k);
  const vec3 xj = rest[j].xyz - p.origin.xyz + disp[j].xyz;
  float t;
  if (!blade_crosses(quad, tool, xi, i, xj, j, t)) return kSideNone;
  crossed = true;
  if (!sides_let(quad, tool, i, xi, j, xj)) return kSideNone;
  const uint side =
      sided ? side_from(normalize(cross(quad.axis.xyz, quad.edge.xyz)), xi, xj) : kSideNone;
  if (pair_weight_bits(k) == 0u || earlier_tool_takes(tool, i, xi, j, xj)) return side;
  claim_pair(i, j, k, t);
  return side;
}

// Merges one lane's sides into candidate i's entry for the tool (side_entry, side_after_lapse):
// the side at the pass's start as it was (readers apply the lapse), then the kept side, or what
// this lane cut i to (none where the kept side lapsed in this pass); both sides (3) read as none
// in the next substep. A side learned in this pass (none at its start)
// gets the plane's normal: every lane writes the same word, which no reader needs before the
// next pass.
void merge_side(uint tool, uint i, uint start, uint side_i, uint cut_to, vec3 normal) {
  const uint index = tool * p.phyxels + i;
  const uint share = side_after_lapse(start, side_i, cut_to);
  if (start == kSideNone && share != kSideNone)
    sides[side_normal_index(tool, p.tools, p.phyxels, i)] = pack_side_normal(normal);
  uint old = sides[index];
  for (;;) {
    const bool stamped = (old >> 4) == (p.pass & kSidePassMask);
    const uint want = (stamped ? old : side_entry(p.pass, start, kSideNone)) | share;
    if (want == old) return;
    const uint seen = atomicCompSwap(sides[index], old, want);
    if (seen == old) return;
    old = seen;
  }
}

// Candidate i's pairs (every lanes-th from `lane`) against each blade; its side entries.
void sever_candidate(uint i, uint lane, uint lanes, bool severing) {
  const vec3 xi = rest[i].xyz - p.origin.xyz + disp[i].xyz;
  const uint end = offset[i + 1u];
  for (uint tool = 0u; tool < p.tools; ++tool) {
    const CutQuad quad = quads[p.row * p.tools + tool];
    if (quad.edge.w < 0.0) continue;  // no blade
    const bool sided = quad.edge.w > 0.0;
    const uint start = sided ? side_at_start(sides[tool * p.phyxels + i], p.pass) : kSideNone;
    const uint side_i = sided ? side_of(tool, quad, i, xi) : kSideNone;
    uint cut_to = kSideNone;
    bool crossed = false;
    if (severing && tool_severs(quad, blade_cuts(tool, quad)))
      for (uint k = offset[i] + lane; k < end; k += lanes)
        cut_to |= sever_pair(tool, quad, i, xi, k, crossed);
    if (!sided) continue;
    merge_side(tool, i, start, side_i, cut_to, edge_frame(quad).normal);  // every substep
    // In tissue, cutting and advancing: the blade stays in the cutting state (every lane that
    // crossed a pair writes the same word, which the next pass reads).
    if (crossed && quad.frame_edge.w > 0.0 && blade_cuts(tool, quad))
      sides[blade_state_index(tool, p.tools, p.phyxels, p.pass & 1u)] = p.pass + 1u;
  }
}

// Without kept sides (kSeverSided false: no blade has a threshold): pair (i, j) at slot k of
// candidate i severed by the first tool whose blade crosses it, each tool's quad read per pair
// (kept live across the pair loop, as sever_candidate does, the pass took 18 % longer at breast
// K = 2.5).
void sever_unsided_pair(uint i, vec3 xi, uint k, uint j, vec3 xj) {
  for (uint tool = 0u; tool < p.tools; ++tool) {
    float t;
    if (!blade_takes(quads[p.row * p.tools + tool], tool, i, xi, j, xj, t)) continue;
    claim_pair(i, j, k, t);
    return;
  }
}

vec3 position(uint x) {
  return rest[x].xyz - p.origin.xyz + disp[x].xyz;
}

// A lane's candidate and (without sides) its first pair: slot first, its weight bits, neighbour
// j at xj; loaded before the blades' balls are set up (their barrier), the weight and the index
// together (one load's wait, not two: the pass 9.7 -> 9.4 us at breast K = 1).
struct LaneStart {
  uint i;
  vec3 xi;
  uint first;
  uint end;
  uint bits;
  uint j;
  vec3 xj;
};

LaneStart lane_start(uint slot, uint lane) {
  LaneStart s = LaneStart(0u, vec3(0.0), 0u, 0u, 0u, 0u, vec3(0.0));
  if (slot >= count.total) return s;
  s.i = list[slot];
  if (kSeverSided) return s;  // sever_candidate loads the rest
  s.xi = position(s.i);
  s.first = offset[s.i] + lane;
  s.end = offset[s.i + 1u];
  if (s.first >= s.end) return s;
  s.bits = pair_weight_bits(s.first);
  s.j = nbr_index(s.first);
  if (s.bits != 0u) s.xj = position(s.j);
  return s;
}

// The lane's pairs, every lanes-th of candidate s.i's from s.first (the first loaded before).
void sever_unsided(LaneStart s, uint lanes) {
  if (s.first < s.end && s.bits != 0u) sever_unsided_pair(s.i, s.xi, s.first, s.j, s.xj);
  for (uint k = s.first + lanes; k < s.end; k += lanes) {
    const uint j = nbr_index(k);
    if (pair_weight_bits(k) == 0u) continue;
    sever_unsided_pair(s.i, s.xi, k, j, position(j));
  }
}

// Whether phyxel x is in the stress pass's list (ascending).
bool in_stress_list(uint x) {
  uint lo = 0u, hi = p.stress_count;
  while (lo < hi) {
    const uint mid = (lo + hi) / 2u;
    if (stress_list[mid] < x) lo = mid + 1u; else hi = mid;
  }
  return lo < p.stress_count && stress_list[lo] == x;
}

// solver_stress's D_i by one invocation: lane q's sum over neighbours q, q + lanes, ..., then
// the lanes' sums added in lane order, as that pass does.
void redo_stress(uint i) {
  const uint fl = flags[i];
  const SolverClass cls = classes[fl >> kFlagClassShift];
  const vec4 li = local_pos[i];
  const vec3 ui = disp[i].xyz;
  const bool stored = stored_weights(p.stress_weights, fl);
  const uint first = offset[i], end = offset[i + 1u];
  mat3 m = mat3(0.0);
  for (uint q = 0u; q < p.stress_lanes; ++q) {
    mat3 lane_m = mat3(0.0);
    for (uint k = first + q; k < end; k += p.stress_lanes) {
      const uint j = nbr_index(k);
      const vec3 x = local_pos[j].xyz - li.xyz;
      const float w = stored ? pair_weight(k) : poly6_weight(dot(x, x), cls.kernel);
      add_stress_pair(lane_m, w, disp[j].xyz - ui, x);
    }
    if (q == 0u) m = lane_m; else m += lane_m;
  }
  Strain s;
  mat3 piola;
  store_stress(i, fl, cls, li.w, ui, m, s, piola);
}

shared bool stress_seen;  // the wait's outcome, for every invocation of the last workgroup

// By the last workgroup, after the dirty list's precompute: once the stress pass beside this one
// has written all its stress, that of the dirty phyxels in its list from their new pairs.
void redo_dirty_stress() {
  const uint dirtied = dirty[0];
  if (p.stress_epoch == 0u || dirtied == 0u) return;  // uniform
  memoryBarrierBuffer();  // the precompute's writes
  barrier();
  // Bounded: Vulkan does not promise that the stress pass, recorded first, runs beside or
  // before this one. Where the wait runs out, the log's header says so (the host throws after
  // the advance) and the redo is skipped.
  if (gl_LocalInvocationIndex == 0u) {
    // Once a wait of the advance ran out, none waits again (one timeout an advance). Seen is
    // what the loop read, not its count: llvmpipe ends any loop after 65 535 iterations.
    bool seen = false;
    const bool missed = atomicAdd(cut_log[0].y, 0u) != 0u;
    for (uint spins = 0u; !missed && spins < kSeverStressWaitSpins; ++spins) {
      if (atomicAdd(stress_finished, 0u) == p.stress_epoch) {
        seen = true;
        break;
      }
    }
    stress_seen = seen;
    if (!seen) atomicOr(cut_log[0].y, kCutLogStressMissed);
  }
  barrier();
  if (!stress_seen) return;  // uniform (shared)
  memoryBarrierBuffer();
  for (uint e = gl_LocalInvocationIndex; e < dirtied; e += gl_WorkGroupSize.x) {
    const uint i = dirty[1u + e];
    if (in_stress_list(i)) redo_stress(i);
  }
}

void main() {
  const uint invocation = PHYXEL_GLOBAL_INDEX;
  const uint lanes = sever.lanes;
  const uint slot = invocation / lanes;
  const uint lane = invocation % lanes;
  const LaneStart s = lane_start(slot, lane);
  const bool severing = any_tool_severs();  // every invocation: it fills blade_ball
  if (slot < count.total) {
    if (kSeverSided)
      sever_candidate(s.i, lane, lanes, severing);
    else if (severing)
      sever_unsided(s, lanes);
  }
  if (finished_last()) {
    precompute_listed();
    redo_dirty_stress();
  }
}
