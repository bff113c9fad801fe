// The edge's resistance (engine/solver/cutting.h EdgeFrame, edge_holds of cutting.cpp) from a
// CutQuad, in float: the pairs a blade with a threshold has passed without severing them.
// Include after layout.h.
#ifndef PHYXEL_BLADE_EDGE_GLSL
#define PHYXEL_BLADE_EDGE_GLSL

struct EdgeFrame {
  vec3 tip;
  vec3 axis;
  vec3 edge;
  vec3 normal;
  float span;  // the blade's length
  float front;  // the body's radius
  float side_band;  // how far across its plane a kept side holds (side_band of cutting.cpp)
  float depth;
  float stiffness;
  float tip_motion;
  float end_motion;
};

EdgeFrame edge_frame(CutQuad c) {
  EdgeFrame f;
  f.edge = c.frame_edge.xyz;
  f.tip = c.frame_tip.xyz;
  f.axis = c.frame_axis.xyz;
  f.normal = normalize(cross(f.axis, f.edge));
  f.span = c.frame_tip.w;
  f.front = c.frame_axis.w;
  f.side_band = c.p1.w;
  f.depth = c.resist.y;
  f.stiffness = c.resist.x;
  f.tip_motion = c.resist.z;
  f.end_motion = c.resist.w;
  return f;
}

// Where the pair p -> q crosses the blade's plane within its span (edge_crossing of
// engine/solver/cutting.cpp): t its fraction, behind how far behind the body's front against
// the motion there (m), moved that motion along the edge; false where it does not cross or the
// blade does not move there.
bool edge_crossing(vec3 p, vec3 q, EdgeFrame f, out float t, out float behind, out float moved) {
  t = 0.0;
  behind = 0.0;
  moved = 0.0;
  const vec3 pt = p - f.tip;
  const float dp = dot(f.normal, pt), dq = dot(f.normal, q - f.tip);
  if ((dp >= 0.0) == (dq >= 0.0)) return false;
  t = dp / (dp - dq);
  const vec3 c = pt + t * (q - p);
  const float along = dot(c, f.axis);
  if (along < 0.0 || along > f.span) return false;
  moved = f.tip_motion + along / f.span * (f.end_motion - f.tip_motion);
  if (moved == 0.0) return false;
  behind = f.front - (moved > 0.0 ? 1.0 : -1.0) * dot(c, f.edge);
  return true;
}

// Whether the edge holds the pair p -> q (canonical order): t its crossing's fraction, behind
// how far behind the body's front it lies (m), against the motion there (direction +-1).
bool edge_holds(vec3 p, vec3 q, EdgeFrame f, out float t, out float behind, out float direction) {
  float moved;
  const bool crosses = edge_crossing(p, q, f, t, behind, moved);
  direction = moved > 0.0 ? 1.0 : -1.0;
  return crosses && behind > 0.0 && behind <= f.depth;
}

// Whether the edge pushes the held pair p -> q (edge_pushes of cutting.cpp): as edge_holds,
// within f.depth times the motion there over the faster end's (nothing at a turned blade's pivot).
bool edge_pushes(vec3 p, vec3 q, EdgeFrame f, out float t, out float behind, out float direction) {
  float moved;
  const bool crosses = edge_crossing(p, q, f, t, behind, moved);
  direction = moved > 0.0 ? 1.0 : -1.0;
  return crosses && behind > 0.0 &&
         behind <= f.depth * abs(moved) / max(abs(f.tip_motion), abs(f.end_motion));
}

// Whether the edge carries the pair p -> q (canonical order) past its reach in this substep
// (edge_passes of cutting.cpp): more than depth, at most depth plus the motion there, behind.
bool edge_passes(vec3 p, vec3 q, EdgeFrame f, out float t) {
  float behind;
  float moved;
  return edge_crossing(p, q, f, t, behind, moved) && behind > f.depth &&
         behind <= f.depth + abs(moved);
}

// One side per phyxel while a blade passes (engine/solver/cutting.h side_entry, sides_allow):
// entry = pass << 4 | side at the pass's start << 2 | side after it. The side buffer holds the
// entries [tool][phyxel], then the normals they were learned on [tool][phyxel]
// (side_normal_index).
const uint kSideNone = 0u, kSidePlus = 1u, kSideMinus = 2u;
const uint kSidePassMask = (1u << 28) - 1u;

uint side_at_start(uint entry, uint pass) {
  const uint stamp = entry >> 4;
  if (stamp == (pass & kSidePassMask)) return (entry >> 2) & 3u;
  if (stamp == ((pass - 1u) & kSidePassMask)) return (entry & 3u) == 3u ? kSideNone : entry & 3u;
  return kSideNone;
}

uint side_normal_index(uint tool, uint tools, uint phyxels, uint i) {
  return (tools + tool) * phyxels + i;
}

// After the normals, two words per tool: its blade's cutting state (docs/cutting.md, "Rupture
// and the cutting state"), pass + 1 written in slot pass & 1 by a pass in which it cut, advanced
// and crossed a pair; the next pass reads the other slot (the CPU's blade_cutting_).
uint blade_state_index(uint tool, uint tools, uint phyxels, uint parity) {
  return 2u * tools * phyxels + 2u * tool + parity;
}

uint side_entry(uint pass, uint start, uint after) {
  return (pass & kSidePassMask) << 4 | start << 2 | after;
}

uint side_after(uint start, uint cut) {
  if (start != kSideNone) return start;
  return cut == kSidePlus || cut == kSideMinus ? cut : kSideNone;
}

// The normal a kept side was learned on, from its word (unpack_side_normal of cutting.cpp:
// octahedral, two 16-bit signed fractions).
float side_sign(float v) {
  return v >= 0.0 ? 1.0 : -1.0;
}

vec3 unpack_side_normal(uint word) {
  float u = float(int(word << 16) >> 16) / 32767.0, v = float(int(word) >> 16) / 32767.0;
  const float z = 1.0 - abs(u) - abs(v);
  if (z < 0.0) {
    const float fu = (1.0 - abs(v)) * side_sign(u), fv = (1.0 - abs(u)) * side_sign(v);
    u = fu;
    v = fv;
  }
  return normalize(vec3(u, v, z));
}

// pack_side_normal of cutting.cpp.
uint pack_side_fraction(float v) {
  return uint(int(floor(clamp(v, -1.0, 1.0) * 32767.0 + 0.5))) & 0xffffu;
}

uint pack_side_normal(vec3 n) {
  const vec3 a = n / (abs(n.x) + abs(n.y) + abs(n.z));
  float u = a.x, v = a.y;
  if (a.z < 0.0) {
    u = (1.0 - abs(a.y)) * side_sign(a.x);
    v = (1.0 - abs(a.x)) * side_sign(a.y);
  }
  return pack_side_fraction(u) | pack_side_fraction(v) << 16;
}

// cos(kSideTurn) of engine/solver/cutting.h: how far the blade's plane may turn from the one a
// side was learned on before the side lapses.
const float kSideTurnCos = 0.98480775;

// The kept side that holds for a phyxel at x (side_near_plane of cutting.cpp): none where it
// lies on the blade plane's other side farther than its band, or where the plane has turned
// from the one the side was learned on (`learned`) by more than kSideTurn (a stale side).
uint side_near_plane(uint side, uint learned, EdgeFrame f, vec3 x) {
  if (side == kSideNone) return side;
  const float n = dot(f.normal, x - f.tip);
  if ((side == kSidePlus && n < -f.side_band) || (side == kSideMinus && n > f.side_band))
    return kSideNone;
  if (dot(unpack_side_normal(learned), f.normal) < kSideTurnCos) return kSideNone;
  return side;
}

// side_after_lapse of cutting.cpp: none where the side at the pass's start lapsed in it.
uint side_after_lapse(uint start, uint held, uint cut) {
  return start != kSideNone && held == kSideNone ? kSideNone : side_after(held, cut);
}

uint side_from(vec3 n, vec3 xi, vec3 xj) {
  return dot(n, xi - xj) >= 0.0 ? kSidePlus : kSideMinus;
}

bool sides_allow(uint side_i, uint side_j, vec3 n, vec3 xi, vec3 xj) {
  const uint i_from_j = side_from(n, xi, xj);
  if (side_i != kSideNone && side_i != i_from_j) return false;
  return side_j == kSideNone || side_j == (i_from_j == kSidePlus ? kSideMinus : kSidePlus);
}

#endif
