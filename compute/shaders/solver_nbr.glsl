// Spatial hashing and the support test of the GPU neighbour search (nbr_*.comp). Include after
// layout.h, with PHYXEL_NBR_FLOAT64 defined to 0 or 1 (nbr_pairs.comp, nbr_pairs_f64.comp).
#ifndef PHYXEL_SOLVER_NBR_GLSL
#define PHYXEL_SOLVER_NBR_GLSL

// Bucket of cell c of object `object` (mask = buckets - 1, buckets a power of two). Different
// cells may share a bucket: the search compares every candidate's own cell with the one it
// visits, so a shared bucket costs time, never a duplicate or a wrong pair.
uint cell_bucket(ivec3 c, uint object, uint mask) {
  uint h = uint(c.x) * 0x8da6b343u ^ uint(c.y) * 0xd8163841u ^ uint(c.z) * 0xcb1ab31fu ^
           object * 0x165667b1u;
  h ^= h >> 16;
  h *= 0x7feb352du;
  h ^= h >> 15;
  return h & mask;
}

ivec3 cell_of_point(vec3 local_position, float cell_size) {
  return ivec3(floor(local_position / cell_size));
}

// The support test |x0_j - x0_i|^2 < h^2 (1 - 1e-9) of the CPU (engine/solver/neighbours.cpp).
// Positions are x0 minus the object's centre, split on the host into hi = float(x) and
// lo = float(x - hi), so hi + lo holds x to about 48 bits.
#if PHYXEL_NBR_FLOAT64
// In double (shaderFloat64): the CPU's test to within 1e-15 of h^2, far inside its 1e-9 margin,
// so the pairs are exactly the CPU's (whatever order or fusion the compiler picks).
bool within_support(vec3 hi_i, vec3 lo_i, vec3 hi_j, vec3 lo_j, vec4 search) {
  const dvec3 d = (dvec3(hi_j) + dvec3(lo_j)) - (dvec3(hi_i) + dvec3(lo_i));
  return dot(d, d) < double(search.x) + double(search.y);
}
#else
// In float (devices without shaderFloat64): the bound is h^2 (1 - 1e-5), outside the float
// rounding of r^2. It differs from the CPU's only for pairs with 1 - 1e-5 < r^2 / h^2 < 1 - 1e-9,
// whose poly6 weight is below 1e-15 of the largest: a lattice (sample_scene) has none unless
// h / s is within 1e-5 of the root of an integer.
bool within_support(vec3 hi_i, vec3 lo_i, vec3 hi_j, vec3 lo_j, vec4 search) {
  const vec3 d = (hi_j - hi_i) + (lo_j - lo_i);
  return dot(d, d) < search.z;
}
#endif

#endif  // PHYXEL_SOLVER_NBR_GLSL
