// The look of torn tissue (torn-face splats, splat_accumulate.comp; docs/tearing.md): where
// tissue was pulled apart rather than cut it is darker and bloodier than a clean cut, and
// ragged. (s, t) are the face's rest-plane coordinates in spacings (render/cut_surfels.cpp),
// as for cut_tissue.glsl (include that first: torn_tissue uses its cut_hash).
//   colour  dark torn flesh, with patches of clotted (near black) and fresh (bright) blood
//           where a slow noise is high or low, shreds of paler tissue along a warped ridged
//           noise (strands pulled out of the face, running every way), and a fine mottle;
//   height  a bump of the same shreds and patches (in spacings) that tilts the shading
//           normal per pixel: finer roughness than the surfels' own displacement (one sample
//           per phyxel) can show.
// Both are value noise of a few octaves; each octave fades out where it is finer than the
// pixel's footprint in (s, t), so nothing aliases at a distance.
#ifndef PHYXEL_TORN_TISSUE_GLSL
#define PHYXEL_TORN_TISSUE_GLSL

const vec3 kTornFlesh = vec3(0.48, 0.07, 0.08);   // torn muscle, darker than a cut's red
const vec3 kTornClot = vec3(0.16, 0.015, 0.02);   // clotted blood: near black red
const vec3 kTornBlood = vec3(0.55, 0.02, 0.035);  // fresh blood: saturated, glossy red
const vec3 kTornBruise = vec3(0.30, 0.05, 0.07);  // bruised, browner flesh
const vec3 kTornShred = vec3(0.68, 0.30, 0.30);   // shreds of paler tissue
const float kTornBump = 0.5;                      // bump slope scale (spacings per spacing)

// Value noise in [-1, 1] at p, one lattice cell per unit, quintic interpolation.
float torn_value(vec2 p, int seed) {
  const vec2 i = floor(p);
  const vec2 f = p - i;
  const vec2 u = f * f * f * (f * (f * 6.0 - 15.0) + 10.0);
  const int x = int(i.x), y = int(i.y);
  const float a = cut_hash(x * 73856093 ^ y * 19349663 ^ seed);
  const float b = cut_hash((x + 1) * 73856093 ^ y * 19349663 ^ seed);
  const float c = cut_hash(x * 73856093 ^ (y + 1) * 19349663 ^ seed);
  const float d = cut_hash((x + 1) * 73856093 ^ (y + 1) * 19349663 ^ seed);
  return 2.0 * mix(mix(a, b, u.x), mix(c, d, u.x), u.y) - 1.0;
}

// Octaves of value noise from `frequency` (cells per spacing) up, each faded by the pixel
// footprint (spacings per pixel): weight 1 at two pixels per cell, 0 at one.
float torn_fbm(vec2 p, float frequency, int octaves, float footprint, int seed) {
  float sum = 0.0, weight = 0.5;
  for (int o = 0; o < octaves; ++o) {
    const float visible = clamp(2.0 - 2.0 * footprint * frequency, 0.0, 1.0);
    // Each octave turned by about 37 degrees so that the lattices do not line up.
    const vec2 q = mat2(0.8, 0.6, -0.6, 0.8) * p * frequency + vec2(17.3 * float(o));
    sum += weight * visible * torn_value(q, seed + 101 * o);
    weight *= 0.5;
    frequency *= 2.0;
  }
  return sum;
}

// Shreds: ridges where a warped noise crosses zero, 1 on a ridge and 0 away from it, of a
// width that varies along them, and broken off where a second noise is low (tatters, not a
// net of veins).
float torn_shreds(vec2 st, float footprint) {
  const vec2 warp = vec2(torn_fbm(st, 0.35, 2, footprint, 11), torn_fbm(st, 0.35, 2, footprint, 23));
  const float n = torn_fbm(st + 1.8 * warp, 0.55, 3, footprint, 37);
  const float width = 0.03 + 0.12 * (0.5 + torn_fbm(st, 0.9, 2, footprint, 41));
  const float present = smoothstep(-0.2, 0.1, torn_fbm(st, 0.4, 2, footprint, 131));
  return present * (1.0 - smoothstep(0.0, width, abs(n)));
}

// The bump height in spacings: lumps of a few spacings, finer grain, raised shreds.
float torn_height(vec2 st, float footprint) {
  return 0.6 * torn_fbm(st, 0.45, 5, footprint, 53) + 0.2 * torn_shreds(st, footprint);
}

vec3 torn_tissue(vec2 st, vec2 st_dx, vec2 st_dy) {
  const float footprint = max(max(abs(st_dx.x), abs(st_dx.y)), max(abs(st_dy.x), abs(st_dy.y)));
  const float blood = torn_fbm(st, 0.18, 3, footprint, 71);  // slow patches
  // Flesh from red to a bruised, browner red.
  vec3 c = mix(kTornFlesh, kTornBruise, 0.5 + torn_fbm(st, 0.3, 2, footprint, 61));
  c = mix(c, kTornClot, smoothstep(0.12, 0.32, blood));
  c = mix(c, kTornBlood, 1.0 - smoothstep(-0.30, -0.10, blood));
  c = mix(c, kTornShred, 0.75 * torn_shreds(st, footprint));
  const float mottle = torn_fbm(st, 2.5, 2, footprint, 89);
  return c * (1.0 + 0.45 * mottle);
}

// The shading normal of a torn splat with unit normal n (eye space) and the eye-space
// gradients of s and t (splat ds.xyz, dt.xyz): n tilted against the bump's slope.
vec3 torn_normal(vec3 n, vec3 ds, vec3 dt, vec2 st, vec2 st_dx, vec2 st_dy) {
  const float footprint = max(max(abs(st_dx.x), abs(st_dx.y)), max(abs(st_dy.x), abs(st_dy.y)));
  const float e = 0.05;  // spacings
  const float h = torn_height(st, footprint);
  const float hs = (torn_height(st + vec2(e, 0.0), footprint) - h) / e;
  const float ht = (torn_height(st + vec2(0.0, e), footprint) - h) / e;
  const vec3 s_dir = length(ds) > 0.0 ? normalize(ds) : vec3(0.0);
  const vec3 t_dir = length(dt) > 0.0 ? normalize(dt) : vec3(0.0);
  return normalize(n - kTornBump * (hs * s_dir + ht * t_dir));
}

#endif  // PHYXEL_TORN_TISSUE_GLSL
