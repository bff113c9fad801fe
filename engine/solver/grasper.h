// The grasper (issue #11, docs/grasper.md): jaws that close on the tissue within reach of the
// tool's tip and carry it rigidly with the tool until they let go. The CPU reference
// (solver/cpu_solver_grasp.cpp) applies it; the GPU solver mirrors it
// (compute/gpu_solver_grasp.cpp, compute/shaders/tool_grasp.comp).
//
// Capture. In the first substep whose middle lies in [from, until) (ToolMotion::grip_closed),
// after the contact pass, the jaws take every candidate phyxel of the contact pass (neither fixed
// nor removed; the broad phase grows a grasper's bounds by its reach) within `reach` of the tip
// at the substep's end pose, in ascending order. Each keeps its offset from the tip in the tool's
// frame: the frame whose z axis is the tool's axis, reached by the shortest rotation (the one
// carry_point turns the tool by), so the offset follows the tool's translation and the turning
// of its axis.
//
// Hold. In every substep the jaws are closed, after the contact pass, each held phyxel is put
// where the tool carries its offset and given the velocity of that point of the tool over the
// substep: x = grip_point(to, offset), v = (grip_point(to, offset) - grip_point(from, offset)) /
// dt. The grip's force on it is m dv / dt, and the tool feels minus the sum: the pull of the
// tissue on the jaws (with the inertia of what they hold). Removed phyxels leave the grip.
//
// Release. In the first substep whose middle is past `until` the grip empties; the phyxels move
// freely from the velocity they had.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/solver/contact.h"

namespace phyxel {

// A held phyxel and its offset from the tip in the tool's frame (m).
struct GripEntry {
  uint32_t phyxel = 0;
  Vec3 offset = Vec3::Zero();
};

// One grasper's jaws: open, or closed on the phyxels in `held` (ascending).
struct Grip {
  bool closed = false;
  std::vector<GripEntry> held;
};

// Whether x is within the jaws' reach of the tip at `pose`.
inline bool in_grasp_reach(const ToolPose& pose, double reach, const Vec3& x) {
  return (x - pose.position).squaredNorm() <= reach * reach;
}

// x's offset from the tip in the tool's frame at `pose`, and back.
inline Vec3 grip_offset(const ToolPose& pose, const Vec3& x) {
  return rotate_with_axis(pose.axis, Vec3::UnitZ(), x - pose.position);
}
inline Vec3 grip_point(const ToolPose& pose, const Vec3& offset) {
  return pose.position + rotate_with_axis(Vec3::UnitZ(), pose.axis, offset);
}

// Where a held phyxel is at the end of a substep of `motion` and its velocity over it.
struct GripTarget {
  Vec3 position, velocity;
};
inline GripTarget grip_target(const ToolMotion& motion, const Vec3& offset, double dt) {
  const Vec3 to = grip_point(motion.to, offset);
  return {to, (to - grip_point(motion.from, offset)) / dt};
}

}  // namespace phyxel
