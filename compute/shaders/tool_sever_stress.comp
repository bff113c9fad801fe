// The stress pass and the sever beside it as one dispatch (GpuSolver's sever beside the stress
// pass): workgroups [0, p.stress_groups) run solver_stress's pass over its list (kStressOnly),
// the rest tool_sever's (tool_sever.glsl), and the one that finishes last reruns the dirty list's
// precompute and redoes the stress of its phyxels in the list: the bits of the two passes in
// turn, one dispatch (no second kernel's launch, no wait for another dispatch).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#define PHYXEL_SEVER_WITH_STRESS
#include "tool_sever.glsl"
