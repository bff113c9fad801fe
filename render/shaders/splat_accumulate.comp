// Pass 2 of 3 with a 32-bit atomicAdd per channel (splat_accumulate.glsl): the fallback where
// the device lacks shaderBufferInt64Atomics.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "splat_accumulate.glsl"
