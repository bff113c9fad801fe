// The splat quad of the accumulation pass (see splat_quad.glsl).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "splat_common.glsl"
#include "splat_quad.glsl"
