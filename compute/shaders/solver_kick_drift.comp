// The opening of an advance(): first half kick and drift of the first step, for the phyxels of
// the force pass list, with f for u at entry: v <- (v + dt/2 f/m) / (1 + c dt/2);
// u_out = u_in + dt v. Fixed phyxels in the list (pass selection off) copy u. disp_in and
// disp_out may be the same buffer (each invocation reads and writes only its own phyxel).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "solver_mls.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { StepPush p; };
layout(std430, binding = kKickDriftBindingDispIn) readonly buffer DispIn { vec4 disp_in[]; };
layout(std430, binding = kKickDriftBindingDispOut) writeonly buffer DispOut { vec4 disp_out[]; };
layout(std430, binding = kKickDriftBindingVel) buffer Vel { vec4 vel[]; };
layout(std430, binding = kKickDriftBindingForce) readonly buffer Force { vec4 force[]; };
layout(std430, binding = kKickDriftBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kKickDriftBindingFlags) readonly buffer Flags { uint flags[]; };
layout(std430, binding = kKickDriftBindingClasses) readonly buffer Classes {
  SolverClass classes[];
};
layout(std430, binding = kKickDriftBindingList) readonly buffer List { uint pass_list[]; };

void main() {
  const uint slot = PHYXEL_GLOBAL_INDEX;
  if (slot >= p.count) return;
  const uint i = pass_list[slot];
  const uint fl = flags[i];
  const vec3 u = disp_in[i].xyz;
  if (!moves(fl)) {
    disp_out[i] = vec4(u, 0.0);
    return;
  }
  const float damping = classes[fl >> kFlagClassShift].elastic.w;
  const vec3 v = half_kick(vel[i].xyz, force[i].xyz, ext[i].w, damping, 0.5 * p.dt);
  vel[i] = vec4(v, 0.0);
  disp_out[i] = vec4(drift(u, v, p.dt), 0.0);
}
