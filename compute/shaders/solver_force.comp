// The force pass (solver_force.glsl) alone: the solver without tearing, and compute_forces.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "solver_force.glsl"

void main() {
  force_pass(PHYXEL_GLOBAL_INDEX);
}
