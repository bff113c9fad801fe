// The colour of cut tissue (cut-face splats, splat_accumulate.comp): a deep, wet red, darker
// and more saturated than the outer surface's texture, with fine fibres. (s, t) are the face's
// rest-plane coordinates in spacings (render/cut_surfels.cpp): the fibres run along s, about
// kFibres across each spacing, wavy, each with its own shade. Procedural (no texture), so the
// outer surface's texture is never reused; filtered by the pixel's footprint in (s, t): fibres
// finer than a pixel fade to their mean colour instead of aliasing.
#ifndef PHYXEL_CUT_TISSUE_GLSL
#define PHYXEL_CUT_TISSUE_GLSL

const float kFibres = 3.0;                        // fibres per spacing across t
const vec3 kCutBase = vec3(0.56, 0.07, 0.11);     // between fibres: deep red
const vec3 kCutFibre = vec3(0.78, 0.20, 0.25);    // fibre centres: red-pink
const vec3 kCutMean = vec3(0.65, 0.125, 0.17);    // their mean (ridge 0.42): a blurred fibre

// An integer hash to [0, 1) (a pcg step), for per-fibre variation that is the same everywhere.
float cut_hash(int n) {
  uint v = uint(n) * 747796405u + 2891336453u;
  v = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
  return float((v >> 22u) ^ v) / 4294967296.0;
}

vec3 cut_tissue(vec2 st, vec2 st_dx, vec2 st_dy) {
  // Wavy fibres: the coordinate across them bends slowly along them.
  const float across = kFibres * (st.y + 0.08 * sin(1.7 * st.x) + 0.05 * sin(4.3 * st.x + 1.3));
  const float fibre = floor(across);
  const float f = across - fibre;
  // A soft ridge per fibre, each with its own height and a slightly shifted centre.
  const float centre = 0.5 + 0.2 * (cut_hash(int(fibre)) - 0.5);
  const float ridge = exp(-18.0 * (f - centre) * (f - centre));
  const float shade = 0.75 + 0.5 * cut_hash(int(fibre) + 7919);
  // The footprint across the fibres, in fibres per pixel: fade the pattern from 0.5 to 1.
  const float footprint = kFibres * max(abs(st_dx.y), abs(st_dy.y));
  const float detail = clamp(2.0 - 2.0 * footprint, 0.0, 1.0);
  const vec3 fibres = mix(kCutBase, kCutFibre, ridge) * shade;
  return mix(kCutMean, fibres, detail);
}

#endif  // PHYXEL_CUT_TISSUE_GLSL
