// Tool-tissue contact of one phyxel in float: the GLSL twin of engine/geometry/tool.cpp
// (perpendicular, rotation_between, tool_distance, carry_point) and of contact_correction in
// engine/solver/contact.cpp (see contact.h for the response). Positions are relative to the
// chunk's origin (ContactPush.origin), which the caller subtracts from the phyxel's position.
// Include after layout.h.
#ifndef PHYXEL_TOOL_CONTACT_GLSL
#define PHYXEL_TOOL_CONTACT_GLSL

// Cross product written out and `precise`, so that cross(a, a) is exactly 0 (a fused
// multiply-add would leave the rounding of one product) and the rotation of an unchanged axis
// is exactly the identity, as on the CPU.
vec3 tool_cross(vec3 a, vec3 b) {
  precise vec3 c = vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
  return c;
}

// A unit vector perpendicular to the unit vector a by the CPU's fixed rule: the basis vector
// least aligned with a, crossed with a.
vec3 tool_perpendicular(vec3 a) {
  const vec3 m = abs(a);
  const vec3 e = (m.x <= m.y && m.x <= m.z) ? vec3(1.0, 0.0, 0.0)
                 : (m.y <= m.z)             ? vec3(0.0, 1.0, 0.0)
                                            : vec3(0.0, 0.0, 1.0);
  return normalize(tool_cross(a, e));
}

// R y - y for the shortest rotation R taking unit a to unit b (the CPU's rotation_between:
// about a x b by atan2(|a x b|, a.b); half a turn about tool_perpendicular(a) for opposite
// axes), by Rodrigues' formula with 1 - cos written as 2 sin^2(theta / 2).
vec3 tool_rotation_offset(vec3 a, vec3 b, vec3 y) {
  const float c = clamp(dot(a, b), -1.0, 1.0);
  const vec3 k = tool_cross(a, b);
  const float s = length(k);
  vec3 axis;
  float sin_t;
  float one_minus_cos;
  if (s < 1e-12) {
    if (c > 0.0) return vec3(0.0);
    axis = tool_perpendicular(a);
    sin_t = 0.0;
    one_minus_cos = 2.0;
  } else {
    axis = k / s;
    const float theta = atan(s, c);
    const float h = sin(0.5 * theta);
    sin_t = sin(theta);
    one_minus_cos = 2.0 * h * h;
  }
  return sin_t * tool_cross(axis, y) + one_minus_cos * (axis * dot(axis, y) - y);
}

// Signed distance from x to the tool's surface at a pose and the outward unit normal
// (tool_distance): a fixed perpendicular to the axis for a point on the capsule's segment,
// minus the axis at a sphere's centre.
struct ToolHit {
  float distance;
  vec3 normal;
};

ToolHit tool_distance(ContactToolShape tool, vec3 position, vec3 axis, vec3 x) {
  const float radius = tool.shape.x;
  const float len = tool.kind.x == kToolCapsule ? tool.shape.y : 0.0;
  const vec3 d = x - position;
  const float along = clamp(dot(d, axis), 0.0, len);
  const vec3 off = d - along * axis;
  const float r = length(off);
  ToolHit hit;
  hit.distance = r - radius;
  if (r > 1e-12 * radius) {
    hit.normal = off / r;
  } else {
    hit.normal = len > 0.0 ? tool_perpendicular(axis) : -axis;
  }
  return hit;
}

// kept_side_exit of engine/solver/contact.cpp: a phyxel kept on one side (keep: the unit normal
// toward it, else zero) inside the capsule beside its segment leaves it along keep.
bool kept_side_exit(ContactToolShape tool, vec3 position, vec3 axis, vec3 x, vec3 keep,
                    inout ToolHit hit) {
  if (keep == vec3(0.0) || tool.kind.x != kToolCapsule) return false;
  const vec3 r = x - position;
  const float along = dot(r, axis);
  if (!(along > 0.0 && along < tool.shape.y)) return false;  // the caps keep their normal
  const vec3 off = r - along * axis;
  const float b = dot(off, keep), a2 = dot(off, off) - b * b;
  const float exit = sqrt(max(0.0, tool.shape.x * tool.shape.x - a2)) - b;
  if (!(exit > 0.0)) return false;
  hit.distance = -exit;
  hit.normal = keep;
  return true;
}

// contact_correction over a substep of dt: x_new is the phyxel's position after the drift
// (relative to the origin), v its velocity, so x_new - x_prev = dt v. Returns false (dx, dv
// untouched) when the phyxel is outside the tool at the end pose; `hold`: the tool rests at
// the end pose (from = to). Position: out along the normal, the tangential slip relative to the
// tool surface removed within the friction cone of that; velocity: relative to the surface's,
// the normal part into the tool removed and the tangential part within mu of that change.
bool tool_contact_correction(ContactToolShape tool, ContactMotion motion, bool hold, float dt,
                             vec3 x_new, vec3 v, vec3 keep, out vec3 dx, out vec3 dv) {
  dx = vec3(0.0);
  dv = vec3(0.0);
  const vec3 to_p = motion.to_position.xyz;
  const vec3 to_a = motion.to_axis.xyz;
  const vec3 from_p = hold ? to_p : motion.from_position.xyz;
  const vec3 from_a = hold ? to_a : motion.from_axis.xyz;
  ToolHit hit = tool_distance(tool, to_p, to_a, x_new);
  if (!(hit.distance < 0.0)) return false;
  const bool parted = kept_side_exit(tool, to_p, to_a, x_new, keep, hit);
  const vec3 n = hit.normal;
  // A blade's sharp point (on_sharp_point): its cap ahead of the tip takes no friction.
  const float mu =
      (parted || (tool.kind.y != 0u && dot(x_new - to_p, to_a) < 0.0)) ? 0.0 : tool.shape.z;
  const vec3 dn = -hit.distance * n;
  const vec3 step = dt * v;
  const vec3 x_prev = x_new - step;
  // carry_point(from, to, x_prev) - x_prev, without the cancellation of world coordinates.
  const vec3 carried = (to_p - from_p) + tool_rotation_offset(from_a, to_a, x_prev - from_p);
  const vec3 rel = step + dn - carried;  // x_new + dn - x_prev - carried
  const vec3 slip = rel - dot(rel, n) * n;
  const float slip_norm = length(slip);
  const float slip_limit = mu * length(dn);
  vec3 dx_t = vec3(0.0);
  if (slip_norm > 0.0) dx_t = -slip * min(1.0, slip_limit / slip_norm);
  const vec3 vr = v - carried / dt;
  const float vn = dot(vr, n);
  const vec3 dv_n = vn < 0.0 ? -vn * n : vec3(0.0);
  const vec3 vt = vr - vn * n;
  const float vt_norm = length(vt);
  const float vt_limit = mu * length(dv_n);
  vec3 dv_t = vec3(0.0);
  if (vt_norm > 0.0) dv_t = -vt * min(1.0, vt_limit / vt_norm);
  dx = dn + dx_t;
  dv = dv_n + dv_t;
  return true;
}

// One tool's step of tool_contact on a phyxel (also solver_force_tear's with kForceContact, so
// both give the same bits): the contact correction of u and v, then the aspirator's pull
// (engine/solver/suction.h suction_pull). felt: the force on the phyxel and 1 where in contact;
// along: the axial range of a contact or of a phyxel in a blade's band. `takes`: not fixed or
// removed; x0: the rest position relative to the origin; volume: the rest volume; keep: the
// blade's side for the phyxel (kept_side_exit).
void contact_tool(ContactToolShape tool, ContactMotion m, bool hold, float dt, bool takes,
                  float mass, float volume, vec3 x0, vec3 keep, inout vec3 u, inout vec3 v,
                  inout uint touched, inout bool moved, out vec4 felt, out vec2 along) {
  felt = vec4(0.0);
  along = vec2(kNoContactAxial, -kNoContactAxial);
  vec3 dx;
  vec3 dv;
  bool around = false;
  if (takes && tool_contact_correction(tool, m, hold, dt, x0 + u, v, keep, dx, dv)) {
    u += dx;
    v += dv;
    felt = vec4(mass * dv / dt, 1.0);
    touched = 1u;
    moved = true;
    around = true;
  } else if (takes && tool.shape.w > 0.0) {
    around = tool_distance(tool, m.to_position.xyz, m.to_axis.xyz, x0 + u).distance < tool.shape.w;
  }
  if (around) along = vec2(dot(x0 + u - m.to_position.xyz, m.to_axis.xyz));
  const vec4 suction = tool.suction;
  if (takes && suction.x > 0.0 && m.to_position.w > 0.0) {
    const vec3 r = x0 + u - m.to_position.xyz;
    const float len = length(r);
    if (dot(r, r) <= suction.y * suction.y && dot(r, m.to_axis.xyz) <= 0.0 && len > 0.0) {
      // The flow's factor (suction_flow_factor): w, the speed toward the tip relative to the
      // tool, and the whole pull's kick against the flow speed suction.z.
      const vec3 tool_v = (m.to_position.xyz - m.from_position.xyz) / dt;
      const float w = dot(v - tool_v, -r / len);
      const float kick = dt / mass * suction.x * volume;
      float factor = clamp(1.0 - w / suction.z, 0.0, 1.0);
      if (kick > suction.z) factor *= suction.z / kick;
      const vec3 pull = factor * suction.x * volume / len * -r;
      v += dt / mass * pull;
      felt.xyz += pull;
      moved = true;
    }
  }
}

#endif  // PHYXEL_TOOL_CONTACT_GLSL
