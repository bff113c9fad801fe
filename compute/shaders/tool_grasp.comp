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
#include "last_workgroup.glsl"

shared vec4 partial[PHYXEL_WORKGROUP_SIZE];
shared uint taken[PHYXEL_WORKGROUP_SIZE];

const vec3 kToolFrameAxis = vec3(0.0, 0.0, 1.0);

// grip_point: where the tool at (position, axis) holds an offset of its frame.
vec3 grip_point(vec3 position, vec3 axis, vec3 offset) {
  return position + offset + tool_rotation_offset(kToolFrameAxis, axis, offset);
}

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
  const vec3 offset = grip[slot].offset.xyz;
  const vec3 to_turn = tool_rotation_offset(kToolFrameAxis, m.to_axis.xyz, offset);
  const vec3 from_turn =
      p.hold != 0u ? to_turn : tool_rotation_offset(kToolFrameAxis, m.from_axis.xyz, offset);
  const vec3 from_p = p.hold != 0u ? m.to_position.xyz : m.from_position.xyz;
  const vec3 x = m.to_position.xyz + offset + to_turn;
  const vec3 v = ((m.to_position.xyz - from_p) + (to_turn - from_turn)) / p.dt;
  const vec3 f = ext[i].w * (v - vel[i].xyz) / p.dt;
  disp[i] = vec4(x - (rest[i].xyz - p.origin.xyz), 0.0);
  vel[i] = vec4(v, 0.0);
  grip_force[slot] = vec4(f, 1.0);
}

void reduce() {
  const uint t = gl_LocalInvocationID.x;
  const uint region = p.tool * p.capacity;
  vec4 sum = vec4(0.0);
  for (uint k = t; k < held[p.tool].total; k += PHYXEL_WORKGROUP_SIZE)
    sum += grip_force[region + k];
  partial[t] = sum;
  barrier();
  for (uint half_size = PHYXEL_WORKGROUP_SIZE / 2u; half_size > 0u; half_size >>= 1u) {
    if (t < half_size) partial[t] += partial[t + half_size];
    barrier();
  }
  if (t == 0u) {
    const uint row = 2u * (p.substep * p.tools + p.tool);
    samples[row].xyz -= partial[0].xyz;
    samples[row + 1u].z = partial[0].w;
  }
}

void main() {
  const ContactMotion m = motion[p.motion * p.tools + p.tool];
  if (p.mode == kGraspCapture) {
    capture(m);
  } else if (p.mode == kGraspHold || p.mode == kGraspHoldReduce) {
    hold(m);
    if (p.mode == kGraspHoldReduce && finished_last()) reduce();
  } else {
    reduce();
  }
}
