// Tool contact after a drift, per candidate phyxel of the chunk's list (tool_broad_phase;
// dispatched indirectly by tool_broad_scan's count): every tool in turn, in the CPU's order
// (CpuSolver::apply_contacts), corrects u and v of the phyxel in place on the displacement
// buffer that holds the new u (u += dx, v += dv), writes the contact force m dv / dt of each
// (candidate, tool) and, for a phyxel in contact or within a blade's band, where it lies along
// the tool's axis from its tip (the rows of tools p.tools onwards) for tool_contact_reduce, and
// sets the phyxel's contact flag. Fixed and
// removed phyxels take no contact (sleeping objects are not in the list). Each invocation reads
// and writes only its own phyxel: no atomics.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "tool_contact.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { ContactPush p; };
layout(std430, binding = kContactBindingList) readonly buffer List { uint list[]; };
layout(std430, binding = kContactBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kContactBindingDisp) buffer Disp { vec4 disp[]; };
layout(std430, binding = kContactBindingVel) buffer Vel { vec4 vel[]; };
layout(std430, binding = kContactBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kContactBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kContactBindingTools) readonly buffer Tools { ContactToolShape tools[]; };
layout(std430, binding = kContactBindingMotion) readonly buffer Motion { ContactMotion motion[]; };
layout(std430, binding = kContactBindingForce) writeonly buffer Force { vec4 contact_force[]; };
layout(std430, binding = kContactBindingContact) writeonly buffer Contact { uint contact[]; };
layout(std430, binding = kContactBindingCount) readonly buffer Count { ContactCount count; };

void main() {
  const uint slot = PHYXEL_GLOBAL_INDEX;
  if (slot >= count.total) return;
  const uint i = list[slot];
  const bool takes = (flags[i] & (kFlagFixed | kFlagRemoved)) == 0u;
  vec3 u = disp[i].xyz;
  vec3 v = vel[i].xyz;
  const float mass = ext[i].w;
  const vec3 x0 = rest[i].xyz - p.origin.xyz;
  uint touched = 0u;
  bool moved = false;
  for (uint t = 0u; t < p.tools; ++t) {
    vec4 felt = vec4(0.0);
    vec4 along = vec4(kNoContactAxial, -kNoContactAxial, 0.0, 0.0);
    vec3 dx;
    vec3 dv;
    const ContactMotion m = motion[p.motion * p.tools + t];
    bool around = false;
    if (takes && tool_contact_correction(tools[t], m, p.hold != 0u, p.dt, x0 + u, v, dx, dv)) {
      u += dx;
      v += dv;
      felt = vec4(mass * dv / p.dt, 1.0);
      touched = 1u;
      moved = true;
      around = true;
    } else if (takes && tools[t].shape.w > 0.0) {
      around = tool_distance(tools[t], m.to_position.xyz, m.to_axis.xyz, x0 + u).distance <
               tools[t].shape.w;
    }
    if (around) along.xy = vec2(dot(x0 + u - m.to_position.xyz, m.to_axis.xyz));
    // The aspirator's pull after the contact (engine/surgery/suction.h suction_pull).
    const vec4 suction = tools[t].suction;
    if (takes && suction.x > 0.0 && m.to_position.w > 0.0) {
      const vec3 r = x0 + u - m.to_position.xyz;
      const float len = length(r);
      if (dot(r, r) <= suction.y * suction.y && dot(r, m.to_axis.xyz) <= 0.0 && len > 0.0) {
        const vec3 pull = suction.x * rest[i].w / len * -r;
        v += p.dt / mass * pull;
        felt.xyz += pull;
        moved = true;
      }
    }
    contact_force[t * p.capacity + slot] = felt;
    contact_force[(p.tools + t) * p.capacity + slot] = along;
  }
  if (moved) {
    disp[i] = vec4(u, 0.0);
    vel[i] = vec4(v, 0.0);
  }
  contact[i] = touched;
}
