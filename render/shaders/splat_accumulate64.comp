// Pass 2 of 3 with one 64-bit atomicAdd per pair of channels (splat_accumulate.glsl): needs
// shaderInt64 and shaderBufferInt64Atomics.
#version 450
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#extension GL_EXT_shader_atomic_int64 : require
#define PHYXEL_ACCUM_INT64
#include "splat_accumulate.glsl"
