// A grasper's jaws in a substep where they are closed (engine/solver/cpu_solver_grasp.cpp is the
// twin; engine/solver/grasper.h the semantics), after tool_contact_reduce. Three modes
// (layout.h GraspPush): capture the candidates within reach when the jaws close (one
// workgroup, in ascending order), hold what the grip has (over its entries, indirect), and
// reduce the grip's forces into the tool's sample (one workgroup, fixed order); or hold, then
// reduce by the workgroup that finishes last.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "tool_contact.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push {
  GraspPush p;
};
layout(std430, binding = kGraspBindingList) readonly buffer List {
  uint list[];
};
layout(std430, binding = kGraspBindingCandidates) readonly buffer Candidates {
  ContactCount candidates;
};
layout(std430, binding = kGraspBindingRest) readonly buffer Rest {
  vec4 rest[];
};
layout(std430, binding = kGraspBindingDisp) buffer Disp {
  vec4 disp[];
};
layout(std430, binding = kGraspBindingVel) buffer Vel {
  vec4 vel[];
};
layout(std430, binding = kGraspBindingExt) readonly buffer Ext {
  vec4 ext[];
};
layout(std430, binding = kGraspBindingFlags) readonly buffer Flags {
  uint flags[];
};
layout(std430, binding = kGraspBindingMotion) readonly buffer Motion {
  ContactMotion motion[];
};
layout(std430, binding = kGraspBindingGrip) buffer Grip {
  GraspEntry grip[];
};
layout(std430, binding = kGraspBindingCount) buffer Count {
  ContactCount held[];
};
layout(std430, binding = kGraspBindingForce) coherent buffer Force {
  vec4 grip_force[];
};
layout(std430, binding = kGraspBindingSamples) buffer Samples {
  vec4 samples[];
};

layout(std430, binding = kGraspBindingDone) coherent buffer Done {
  uint done;
};
layout(std430, binding = kGraspBindingGripOf) writeonly buffer GripOf {
  uint grip_of[];
};
#include "last_workgroup.glsl"
#include "tool_grasp.glsl"

shared uint taken[PHYXEL_WORKGROUP_SIZE];

void capture(ContactMotion m) {
  const uint t = gl_LocalInvocationID.x;
  const uint region = p.tool * p.capacity;
  const vec3 tip = m.to_position.xyz;
  const float reach = p.origin.w;
  const uint total = candidates.total;
  uint base = 0u;
  for (uint start = 0u; start < total; start += PHYXEL_WORKGROUP_SIZE) {
    const uint slot = start + t;
    bool take = false;
    uint i = 0u;
    vec3 r = vec3(0.0);
    if (slot < total) {
      i = list[slot];
      if ((flags[i] & (kFlagFixed | kFlagRemoved)) == 0u) {
        r = rest[i].xyz - p.origin.xyz + disp[i].xyz - tip;
        take = dot(r, r) <= reach * reach;
      }
    }
    taken[t] = take ? 1u : 0u;
    barrier();
    for (uint d = 1u; d < PHYXEL_WORKGROUP_SIZE; d <<= 1u) {  // inclusive scan
      const uint add = t >= d ? taken[t - d] : 0u;
      barrier();
      taken[t] += add;
      barrier();
    }
    if (take) {
      const vec3 offset = r + tool_rotation_offset(m.to_axis.xyz, kToolFrameAxis, r);
      grip[region + base + taken[t] - 1u] = GraspEntry(vec4(offset, 0.0), uvec4(i, 0u, 0u, 0u));
      grip_of[region + i] = base + taken[t] - 1u;
    }
    base += taken[PHYXEL_WORKGROUP_SIZE - 1u];
    barrier();
  }
  if (t == 0u) {
    const uint groups = (base + PHYXEL_WORKGROUP_SIZE - 1u) / PHYXEL_WORKGROUP_SIZE;
    held[p.tool] = ContactCount(base, min(groups, 65535u), (groups + 65534u) / 65535u, 1u);
  }
}

void hold(ContactMotion m) {
  const uint e = PHYXEL_GLOBAL_INDEX;
  if (e >= held[p.tool].total) return;
  const uint slot = p.tool * p.capacity + e;
  const uint i = grip[slot].phyxel.x;
  if ((flags[i] & kFlagRemoved) != 0u) {  // aspirated: no longer held
    grip_force[slot] = vec4(0.0);
    return;
  }
  vec3 u;
  vec3 v;
  grip_hold(m, p.hold != 0u, p.dt, slot, rest[i].xyz - p.origin.xyz, ext[i].w, vel[i].xyz, u, v);
  disp[i] = vec4(u, 0.0);
  vel[i] = vec4(v, 0.0);
}

void main() {
  const ContactMotion m = motion[p.motion * p.tools + p.tool];
  if (p.mode == kGraspCapture) {
    capture(m);
  } else if (p.mode == kGraspHold || p.mode == kGraspHoldReduce) {
    hold(m);
    if (p.mode == kGraspHoldReduce && finished_last())
      grip_reduce(p.tool, p.tools, p.capacity, p.substep);
  } else {
    grip_reduce(p.tool, p.tools, p.capacity, p.substep);
  }
}
