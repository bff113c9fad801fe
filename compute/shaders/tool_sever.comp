// tool_sever: a substep's cut in a pass of its own (tool_sever.glsl).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "tool_sever.glsl"
