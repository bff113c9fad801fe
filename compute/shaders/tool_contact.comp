// Tool contact after a drift, per candidate phyxel of the chunk's list (tool_broad_phase;
// dispatched indirectly by tool_broad_scan's count): every tool in turn, in the CPU's order
// (CpuSolver::apply_contacts), corrects u and v of the phyxel in place on the displacement
// buffer that holds the new u (u += dx, v += dv), sums per workgroup and tool the contact
// forces m dv / dt and, for phyxels in contact or within a blade's band, the range they span
// along the tool's axis from its tip (the rows of tools p.tools onwards) for
// tool_contact_reduce, and sets the phyxel's contact flag. Fixed and
// removed phyxels take no contact (sleeping objects are not in the list). Each invocation reads
// and writes only its own phyxel. With kContactFuseReduce (no tool_resist between the two), the
// workgroup that finishes last (an atomic count of the finished ones) sums the partials into the
// samples as tool_contact_reduce does, in the same order: the same bits, one dispatch and one
// barrier less per substep. With p.grasp a tool, that grasper's hold too (layout_surgery.h
// ContactPush; tool_grasp.glsl): a candidate's hold follows its contact in its invocation, the
// held phyxels that are no candidate are held by every invocation in turn (no two invocations
// touch one phyxel), and the last workgroup subtracts the grip's force from the sample.
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
layout(std430, binding = kContactBindingForce) coherent buffer Force { vec4 contact_force[]; };
layout(std430, binding = kContactBindingContact) writeonly buffer Contact { uint contact[]; };
layout(std430, binding = kContactBindingCount) readonly buffer Count { ContactCount count; };
layout(std430, binding = kContactBindingSamples) buffer Samples { vec4 samples[]; };
layout(std430, binding = kContactBindingDirty) writeonly buffer Dirty { uint dirty[]; };
layout(std430, binding = kContactBindingDone) coherent buffer Done { uint done; };
layout(std430, binding = kContactBindingGrip) readonly buffer Grip { GraspEntry grip[]; };
layout(std430, binding = kContactBindingHeld) readonly buffer Held { ContactCount held[]; };
layout(std430, binding = kContactBindingGripForce) coherent buffer GripForce { vec4 grip_force[]; };
layout(std430, binding = kContactBindingGripOf) readonly buffer GripOf { uint grip_of[]; };
layout(std430, binding = kContactBindingSlot) readonly buffer Slot { uint candidate_slot[]; };
layout(std430, binding = kContactBindingSides) readonly buffer Sides { uint sides[]; };
layout(std430, binding = kContactBindingQuads) readonly buffer Quads { CutQuad quads[]; };

#include "blade_edge.glsl"

// CpuSolver::kept_side: the normal of tool t's blade toward the side it keeps phyxel i on,
// else zero (the cut table's row: past the chunk, the held end pose).
vec3 kept_side(uint t, uint i) {
  if (p.phyxels == 0u) return vec3(0.0);
  const CutQuad quad = quads[(p.motion + p.hold) * p.tools + t];
  if (!(quad.edge.w > 0.0)) return vec3(0.0);  // no blade, or one without a threshold
  const uint side = side_at_start(sides[t * p.phyxels + i], p.pass);
  if (side == kSideNone) return vec3(0.0);
  const vec3 n = normalize(cross(quad.axis.xyz, quad.edge.xyz));
  return side == kSidePlus ? n : -n;
}

#include "tool_contact_sum.glsl"

// Each workgroup adds its candidates' forces and axial ranges per tool (sum_workgroup) and
// writes one partial per tool: tool_contact_reduce adds a workgroup's partials, so its serial
// loop is 64 times shorter than over the candidates (all of a box at 1M phyxels when torn
// pieces fly and the broad phase's margin grows with their speed).
#include "last_workgroup.glsl"
#include "tool_grasp.glsl"

// kContactFuseReduce: after every workgroup wrote its partials, the last one writes the samples.
void fused_reduce() {
  if (!finished_last()) return;
  for (uint t = 0u; t < p.tools; ++t)
    write_tool_sample(t, p.tools, p.capacity, p.substep, count.total);
  // Lane 0 wrote the samples and subtracts the grip's force from them.
  if (p.grasp < p.tools) grip_reduce(p.grasp, p.tools, p.grip_capacity, p.substep);
  if (gl_LocalInvocationIndex != 0u || (p.fuse & kContactFuseDirtyReset) == 0u) return;
  dirty[0] = 0u;  // the count: nothing severed yet
}

// The grasper's hold of candidate i after its contact (u, v: after it), where i is held.
// Returns whether it moved i.
bool hold_candidate(uint i, vec3 x0, float mass, inout vec3 u, inout vec3 v) {
  const uint region = p.grasp * p.grip_capacity;
  const uint e = grip_of[region + i];
  if (e >= held[p.grasp].total || grip[region + e].phyxel.x != i) return false;  // not held
  if ((flags[i] & kFlagRemoved) != 0u) {  // aspirated: no longer held
    grip_force[region + e] = vec4(0.0);
    return false;
  }
  const ContactMotion m = motion[p.motion * p.tools + p.grasp];
  const vec3 v_now = v;
  grip_hold(m, p.hold != 0u, p.dt, region + e, x0, mass, v_now, u, v);
  return true;
}

// The hold of the grip's phyxels that are not candidates of this pass, spread over all its
// invocations.
void hold_others() {
  const uint region = p.grasp * p.grip_capacity;
  const uint stride = gl_NumWorkGroups.x * gl_NumWorkGroups.y * PHYXEL_WORKGROUP_SIZE;
  const ContactMotion m = motion[p.motion * p.tools + p.grasp];
  for (uint e = PHYXEL_GLOBAL_INDEX; e < held[p.grasp].total; e += stride) {
    const uint i = grip[region + e].phyxel.x;
    const uint s = candidate_slot[i];
    if (s < count.total && list[s] == i) continue;  // hold_candidate's
    if ((flags[i] & kFlagRemoved) != 0u) {
      grip_force[region + e] = vec4(0.0);
      continue;
    }
    vec3 u;
    vec3 v;
    grip_hold(m, p.hold != 0u, p.dt, region + e, rest[i].xyz - p.origin.xyz, ext[i].w, vel[i].xyz,
              u, v);
    disp[i] = vec4(u, 0.0);
    vel[i] = vec4(v, 0.0);
  }
}

void main() {
  const uint slot = PHYXEL_GLOBAL_INDEX;
  const uint group = slot / PHYXEL_WORKGROUP_SIZE;
  const uint lane = gl_LocalInvocationIndex;
  const bool candidate = slot < count.total;  // no early return: barriers below
  const uint i = candidate ? list[slot] : 0u;
  const bool takes = candidate && (flags[i] & (kFlagFixed | kFlagRemoved)) == 0u;
  vec3 u = candidate ? disp[i].xyz : vec3(0.0);
  vec3 v = candidate ? vel[i].xyz : vec3(0.0);
  const float mass = candidate ? ext[i].w : 1.0;
  const vec3 x0 = candidate ? rest[i].xyz - p.origin.xyz : vec3(0.0);
  uint touched = 0u;
  bool moved = false;
  const float volume = candidate ? rest[i].w : 0.0;
  for (uint t = 0u; t < p.tools; ++t) {
    vec4 felt;
    vec2 along;
    const vec3 keep = takes ? kept_side(t, i) : vec3(0.0);
    contact_tool(tools[t], motion[p.motion * p.tools + t], p.hold != 0u, p.dt, takes, mass, volume,
                 x0, keep, u, v, touched, moved, felt, along);
    sum_workgroup(felt, along);
    // p.capacity: the partials' stride; a workgroup past the candidates (a dispatch spread
    // over y) writes none.
    if (lane == 0u && group * PHYXEL_WORKGROUP_SIZE < count.total) {
      contact_force[t * p.capacity + group] = wg_felt[0];
      contact_force[(p.tools + t) * p.capacity + group] = vec4(wg_along[0], 0.0, 0.0);
    }
    barrier();  // the next tool's sums reuse the shared arrays
  }
  if (candidate) {
    if (p.grasp < p.tools) moved = hold_candidate(i, x0, mass, u, v) || moved;
    if (moved) {
      disp[i] = vec4(u, 0.0);
      vel[i] = vec4(v, 0.0);
    }
    contact[i] = touched;
  }
  if (p.grasp < p.tools) hold_others();
  if ((p.fuse & kContactFuseReduce) != 0u) {
    fused_reduce();
  } else if ((p.fuse & kContactFuseDirtyReset) != 0u && PHYXEL_GLOBAL_INDEX == 0u) {
    dirty[0] = 0u;  // the samples apart (tool_contact_reduce beside the sever): no one reads it here
  }
}
