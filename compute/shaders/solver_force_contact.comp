// The force pass (solver_force.glsl) with the next substep's tool contact after each drift and
// the grasper's hold (force_contact.glsl), where nothing tears: GpuSolver's contact_in_force_
// for a blade without a threshold and at most one grasper whose jaws do not close in that
// substep. tool_contact's work, the same bits: each force-list phyxel's contact and hold in
// its own invocation, the held phyxels outside the list (asleep, removed) by every invocation
// in turn; the felt forces into rows that tool_contact_reduce sums after the advance, the grip's
// forces summed beside the next stress pass (tool_contact_reduce's grip rows). With
// kForceContactDirtyReset one invocation empties tool_sever's dirty list, as tool_contact did.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#define PHYXEL_FORCE_CONTACT 1
#include "solver_force.glsl"

void main() {
  force_pass(PHYXEL_GLOBAL_INDEX);
  hold_outside_list();
  if ((p.contact_fuse & kForceContactDirtyReset) != 0u && PHYXEL_GLOBAL_INDEX == 0u) dirty[0] = 0u;
}
