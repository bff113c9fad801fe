// The splat quad of the visibility pass: centre and normal only (see splat_quad.glsl).
#version 450
#extension GL_GOOGLE_include_directive : require
#define PHYXEL_SPLAT_DEPTH_ONLY
#include "render_layout.h"
#include "splat_common.glsl"
#include "splat_quad.glsl"
