// A grasper's hold of one phyxel and the reduction of its grip's forces into the tool's sample,
// shared by tool_grasp (kGraspHold, kGraspReduce) and tool_contact (ContactPush.grasp), so that
// both give the same bits. Include after tool_contact.glsl and the buffers grip, held,
// grip_force and samples.
#ifndef PHYXEL_TOOL_GRASP_GLSL
#define PHYXEL_TOOL_GRASP_GLSL

#ifndef PHYXEL_GRIP_HOLD_ONLY  // solver_force_contact holds, tool_contact_reduce sums
#include "grip_reduce.glsl"
#endif

const vec3 kToolFrameAxis = vec3(0.0, 0.0, 1.0);

// The held phyxel of grip entry `slot` (its rest position x0 relative to the origin, its mass,
// its velocity v_now) put where the tool carries its offset: u and v out, and its force
// m dv / dt and 1 into grip_force[slot]. `hold`: the tool rests at the row's end pose.
void grip_hold(ContactMotion m, bool hold, float dt, uint slot, vec3 x0, float mass, vec3 v_now,
               out vec3 u, out vec3 v) {
  const vec3 offset = grip[slot].offset.xyz;
  const vec3 to_turn = tool_rotation_offset(kToolFrameAxis, m.to_axis.xyz, offset);
  const vec3 from_turn =
      hold ? to_turn : tool_rotation_offset(kToolFrameAxis, m.from_axis.xyz, offset);
  const vec3 from_p = hold ? m.to_position.xyz : m.from_position.xyz;
  const vec3 x = m.to_position.xyz + offset + to_turn;
  v = ((m.to_position.xyz - from_p) + (to_turn - from_turn)) / dt;
  const vec3 f = mass * (v - v_now) / dt;
  u = x - x0;
  grip_force[slot] = vec4(f, 1.0);
}

#endif  // PHYXEL_TOOL_GRASP_GLSL
