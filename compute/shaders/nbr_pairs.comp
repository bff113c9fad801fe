// Neighbour search, pair count and fill (nbr_pairs.glsl), with the support test in float
// (any device).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#define PHYXEL_NBR_FLOAT64 0
#include "nbr_pairs.glsl"
