// solver_force_tear's contact (kForceContact in p.contact_fuse): after the drift of the next
// substep, tool_contact's work on a candidate of the force list (contact_tool, the same bits),
// its felt and axial range per tool into the rows that tool_contact_reduce sums after the
// advance (tool_contact sums per substep), and its contact flag. One dispatch and barrier a
// substep fewer. Include in solver_force.glsl after its buffers. In solver_force_contact
// (PHYXEL_FORCE_CONTACT: no tear test) the grasper's hold too: each force-list phyxel's after
// its contact, the held phyxels outside the list by every invocation in turn (tool_contact's
// hold_candidate and hold_others, the same bits).
#ifndef PHYXEL_FORCE_CONTACT_GLSL
#define PHYXEL_FORCE_CONTACT_GLSL

#ifdef PHYXEL_FORCE_CONTACT
#define PHYXEL_FC_BINDING(name) kForceContactBinding##name
#else
#define PHYXEL_FC_BINDING(name) kForceTearBinding##name
#endif

layout(std430, binding = PHYXEL_FC_BINDING(Rest)) readonly buffer Rest {
  vec4 rest[];
};
layout(std430, binding = PHYXEL_FC_BINDING(Slot)) readonly buffer Slot {
  uint candidate_slot[];
};
layout(std430, binding = PHYXEL_FC_BINDING(Count)) readonly buffer Count {
  ContactCount contact_count;
};
layout(std430, binding = PHYXEL_FC_BINDING(Tools)) readonly buffer Tools {
  ContactToolShape tools[];
};
layout(std430, binding = PHYXEL_FC_BINDING(Motion)) readonly buffer Motion {
  ContactMotion motion[];
};
layout(std430, binding = PHYXEL_FC_BINDING(Rows)) writeonly buffer Rows {
  vec4 rows[];
};
layout(std430, binding = PHYXEL_FC_BINDING(Contact)) writeonly buffer Contact {
  uint contact[];
};

#include "tool_contact.glsl"

#ifdef PHYXEL_FORCE_CONTACT
layout(std430, binding = kForceContactBindingDirty) writeonly buffer Dirty { uint dirty[]; };
layout(std430, binding = kForceContactBindingGrip) readonly buffer Grip { GraspEntry grip[]; };
layout(std430, binding = kForceContactBindingHeld) readonly buffer Held { ContactCount held[]; };
layout(std430, binding = kForceContactBindingGripForce) writeonly buffer GripForce {
  vec4 grip_force[];
};
layout(std430, binding = kForceContactBindingGripOf) readonly buffer GripOf { uint grip_of[]; };
layout(std430, binding = kForceContactBindingInForce) readonly buffer InForce {
  uint in_force[];
};
#define PHYXEL_GRIP_HOLD_ONLY
#include "tool_grasp.glsl"

ContactMotion grasp_motion() {
  return motion[p.contact_motion * p.contact_tools + p.contact_grasp];
}

// The hold of phyxel k (flags fl, mass; u and v after its contact) where the grasper holds it
// (tool_contact's hold_candidate). Returns whether it did.
bool force_hold(uint k, uint fl, float mass, inout vec3 u, inout vec3 v) {
  if (p.contact_grasp == kContactNoGrasp) return false;
  const uint region = p.contact_grasp * p.grip_capacity;
  const uint e = grip_of[region + k];
  if (e >= held[p.contact_grasp].total || grip[region + e].phyxel.x != k) return false;
  if ((fl & kFlagRemoved) != 0u) {  // aspirated: no longer held
    grip_force[region + e] = vec4(0.0);
    return false;
  }
  const vec3 v_now = v;
  grip_hold(grasp_motion(), p.contact_hold != 0u, p.dt, region + e,
            rest[k].xyz - p.contact_origin.xyz, mass, v_now, u, v);
  return true;
}

// The held phyxels outside the force list (asleep or removed), spread over all invocations
// (tool_contact's hold_others): no force-list invocation touches them.
void hold_outside_list() {
  if (p.contact_grasp == kContactNoGrasp) return;
  const uint region = p.contact_grasp * p.grip_capacity;
  const uint stride = gl_NumWorkGroups.x * gl_NumWorkGroups.y * PHYXEL_WORKGROUP_SIZE;
  const ContactMotion m = grasp_motion();
  for (uint e = PHYXEL_GLOBAL_INDEX; e < held[p.contact_grasp].total; e += stride) {
    const uint i = grip[region + e].phyxel.x;
    if ((in_force[i >> 5u] & (1u << (i & 31u))) != 0u) continue;  // force_hold's
    if ((flags[i] & kFlagRemoved) != 0u) {
      grip_force[region + e] = vec4(0.0);
      continue;
    }
    vec3 u;
    vec3 v;
    grip_hold(m, p.contact_hold != 0u, p.dt, region + e, rest[i].xyz - p.contact_origin.xyz,
              ext[i].w, vel[i].xyz, u, v);
    disp_out[i] = vec4(u, 0.0);
    vel[i] = vec4(v, 0.0);
  }
}
#endif

// Phyxel k (flags fl, mass) with u and v after the drift: corrected in place where it is a
// candidate of the broad phase (its slot in the list, below the count).
void force_contact(uint k, uint fl, float mass, inout vec3 u, inout vec3 v) {
  const uint slot = candidate_slot[k];
  if (slot >= contact_count.total) return;
  const bool takes = (fl & (kFlagFixed | kFlagRemoved)) == 0u;
  const vec3 x0 = rest[k].xyz - p.contact_origin.xyz;
  const float volume = rest[k].w;
  const uint tool_count = p.contact_tools;
  uint touched = 0u;
  bool moved = false;
  for (uint t = 0u; t < tool_count; ++t) {
    vec4 felt;
    vec2 along;
    contact_tool(tools[t], motion[p.contact_motion * tool_count + t], p.contact_hold != 0u, p.dt,
                 takes, mass, volume, x0, vec3(0.0), u, v, touched, moved, felt, along);  // no blade
    rows[(2u * p.contact_row * tool_count + t) * p.contact_stride + slot] = felt;
    rows[((2u * p.contact_row + 1u) * tool_count + t) * p.contact_stride + slot] =
        vec4(along, 0.0, 0.0);
  }
  contact[k] = touched;
}

#endif  // PHYXEL_FORCE_CONTACT_GLSL
