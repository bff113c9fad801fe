// solver_force_tear's contact (kForceContact in p.contact_fuse): after the drift of the next
// substep, tool_contact's work on a candidate of the force list (contact_tool, the same bits),
// its felt and axial range per tool into the rows that tool_contact_reduce sums after the
// advance (tool_contact sums per substep), and its contact flag. One dispatch and barrier a
// substep fewer. Include in solver_force.glsl after its buffers.
#ifndef PHYXEL_FORCE_CONTACT_GLSL
#define PHYXEL_FORCE_CONTACT_GLSL

layout(std430, binding = kForceTearBindingRest) readonly buffer Rest {
  vec4 rest[];
};
layout(std430, binding = kForceTearBindingSlot) readonly buffer Slot {
  uint candidate_slot[];
};
layout(std430, binding = kForceTearBindingCount) readonly buffer Count {
  ContactCount contact_count;
};
layout(std430, binding = kForceTearBindingTools) readonly buffer Tools {
  ContactToolShape tools[];
};
layout(std430, binding = kForceTearBindingMotion) readonly buffer Motion {
  ContactMotion motion[];
};
layout(std430, binding = kForceTearBindingRows) writeonly buffer Rows {
  vec4 rows[];
};
layout(std430, binding = kForceTearBindingContact) writeonly buffer Contact {
  uint contact[];
};

#include "tool_contact.glsl"

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
