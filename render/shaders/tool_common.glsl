// Shared by tool_visibility.comp and splat_shade.comp: the analytic ray cast of a tool (a ball,
// or a capsule: the segment from the tip along the axis swept by the radius) in eye space,
// and the packing of the hit's normal into one accumulation channel. render/tool_raycast.cpp
// is the CPU twin of the intersection (same formulas, in double).
#ifndef PHYXEL_TOOL_COMMON_GLSL
#define PHYXEL_TOOL_COMMON_GLSL

struct ToolHit {
  float t;      // along the unit ray from the eye
  vec3 normal;  // outward unit normal at the hit
};

// The ray t dir (dir unit, from the eye at the origin) against the ball (c, r): keeps the
// entry when it is nearer than best.t and in front of the eye. The squared distance of the
// ray from the centre comes from the perpendicular offset itself (no cancellation of two
// large squares when the ball is far away and small).
void ball_entry(vec3 dir, vec3 c, float r, inout ToolHit best) {
  const float b = dot(dir, c);
  const vec3 q = c - b * dir;
  const float h = r * r - dot(q, q);
  if (h < 0.0) return;
  const float t = b - sqrt(h);
  if (t > 0.0 && t < best.t) {
    best.t = t;
    best.normal = (t * dir - c) / r;
  }
}

// The same for the side of the cylinder around the segment [p0, p0 + len a] (a unit): only
// entries whose foot on the axis lies within the segment. A ray along the axis meets the
// side nowhere (the balls at the ends take it). h = A r^2 - |d_perp x w_perp|^2 is
// Lagrange's form of B^2 - A C, free of cancellation.
void cylinder_entry(vec3 dir, vec3 p0, vec3 a, float len, float r, inout ToolHit best) {
  const vec3 w = -p0;
  const vec3 d_perp = dir - dot(dir, a) * a;
  const vec3 w_perp = w - dot(w, a) * a;
  const float A = dot(d_perp, d_perp);
  if (!(A > 1e-12)) return;
  const vec3 k = cross(d_perp, w_perp);
  const float h = A * r * r - dot(k, k);
  if (h < 0.0) return;
  const float t = (-dot(w_perp, d_perp) - sqrt(h)) / A;
  const vec3 x = t * dir;
  const float y = dot(x - p0, a);
  if (t > 0.0 && t < best.t && y >= 0.0 && y <= len) {
    best.t = t;
    best.normal = (x - p0 - y * a) / r;
  }
}

// The nearest entry (t > 0) of the ray into the tool with the tip at p0, unit axis a, radius
// r and length len (0: a ball); t = 1e30 when it misses. The capsule is the union of the two
// end balls and the cylinder between them, each convex: the union's entry is the nearest of
// theirs (a ray entering through a flat end of the cylinder enters its ball first).
ToolHit tool_entry(vec3 dir, vec3 p0, vec3 a, float len, float r) {
  ToolHit best;
  best.t = 1e30;
  best.normal = vec3(0.0, 0.0, 1.0);
  ball_entry(dir, p0, r, best);
  if (len > 0.0) {
    ball_entry(dir, p0 + len * a, r, best);
    cylinder_entry(dir, p0, a, len, r, best);
  }
  return best;
}

vec2 sign_not_zero(vec2 v) {
  return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

// kToolHitFlag | octahedral (u, v) of the unit normal n, 15 bits each.
uint pack_tool_normal(vec3 n) {
  n /= abs(n.x) + abs(n.y) + abs(n.z);
  vec2 o = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
  const uvec2 q = uvec2(round(clamp(o * 0.5 + 0.5, 0.0, 1.0) * 32767.0));
  return kToolHitFlag | (q.y << 15) | q.x;
}

vec3 unpack_tool_normal(uint bits) {
  const vec2 o = vec2(bits & 0x7fffu, (bits >> 15) & 0x7fffu) / 32767.0 * 2.0 - 1.0;
  vec3 n = vec3(o, 1.0 - abs(o.x) - abs(o.y));
  if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * sign_not_zero(n.xy);
  return normalize(n);
}

#endif  // PHYXEL_TOOL_COMMON_GLSL
