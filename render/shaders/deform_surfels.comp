// Deformed splats from the solver's buffers (rest, displacement, rest-neighbour CSR lists):
// centre x0 + u, normal n' ~ (I + grad u)^-T n, texture gradients (ds/dx0) F^-1 and a radius
// grown with the tangential stretch, one invocation per surface phyxel.
//
// grad u_i = M_i A_i^-1 (the paper's eq 10) with A_i = sum_j w x_ij x_ij^T and
// M_i = sum_j w (u_j - u_i) x_ij^T over the rest neighbours, w the poly6 kernel of the
// object's support radius h. Lengths are divided by h and w by its constant factor
// 315 / (64 pi h^9): both cancel in M A^-1 and the sums stay of order one in fp32 at any scale.
// kDeformLanes invocations share one surfel: each sums every kDeformLanes-th neighbour of its
// CSR row (so the lanes read the row's indices side by side and keep several gathers in
// flight), the partial sums meet in shared memory, and lane 0 finishes the splat.
//
// Severed pairs (cutting): with DeformPush::pair_weights set, pair e of the CSR lists is left
// out where pair_weight[e] == 0 (the GPU solver's weights, or HostInputs' 0/1 alive mask), so a
// splat next to a cut deforms with its own piece only. Without it a placeholder is bound and
// every pair counts.
//
// A cut-face surfel (kSurfelCutFace) sits on the face the blade left: its centre is moved from
// the phyxel by normal.w along the rest normal, carried through F (x_i + u_i + F n0 d). A torn
// face (kSurfelTornFace) is a cut face whose rest normal and offset carry the fracture noise
// (render/cut_surfels.h); its splat gets kSplatTornFace.
//
// A is inverted as the solver inverts it (compute/shaders/moment_inverse.glsl, regularised
// where ill-conditioned: few or coplanar neighbours, e.g. after a cut), so grad u is the
// solver's. Where A has no weight (no live neighbour) or F is singular, the splat keeps its
// rest normal and texture gradients (normal.w = 0 says so).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "render_layout.h"
#include "moment_inverse.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

layout(push_constant) uniform Push { DeformPush p; };
layout(std430, binding = kDeformBindingRest) readonly buffer Rest { vec4 rest[]; };
layout(std430, binding = kDeformBindingDisplacement) readonly buffer Disp { vec4 disp[]; };
layout(std430, binding = kDeformBindingNbrOffset) readonly buffer Offset { uint nbr_offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kDeformBindingNbrIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kDeformBindingNbrIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kDeformBindingPairWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kDeformBindingPairWeightHi
#define PHYXEL_PAIR_ACCESS 0
#include "pair_buffers.glsl"
layout(std430, binding = kDeformBindingSurfels) readonly buffer Surfels { SurfelStatic surfels[]; };
layout(std430, binding = kDeformBindingSplats) writeonly buffer Splats { Splat splats[]; };

// A unit vector perpendicular to the unit vector n.
vec3 any_tangent(vec3 n) {
  const vec3 a = abs(n.x) < 0.9 ? vec3(1, 0, 0) : vec3(0, 1, 0);
  return normalize(cross(n, a));
}

// Partial sums of A (xx xy xz yy yz zz) and M (column-major) of every lane.
shared float partial_a[PHYXEL_WORKGROUP_SIZE][6];
shared vec3 partial_m[PHYXEL_WORKGROUP_SIZE][3];

void main() {
  const uint lid = gl_LocalInvocationIndex;
  const uint lane = lid % kDeformLanes;
  const uint k = PHYXEL_GLOBAL_INDEX / kDeformLanes;
  const bool live = k < p.count && surfels[min(k, p.count - 1)].index < p.phyxels;
  const uint i = live ? surfels[k].index : 0;
  const float inv_h = live ? 1.0 / surfels[k].support : 0.0;
  float a[6] = float[6](0, 0, 0, 0, 0, 0);
  mat3 M = mat3(0.0);
  if (live) {
    const vec3 xi = rest[i].xyz;
    const vec3 ui = disp[i].xyz;
    const uint end = nbr_offset[i + 1];
    for (uint e = nbr_offset[i] + lane; e < end; e += kDeformLanes) {
      const uint j = nbr_index(e);
      if (j >= p.phyxels) continue;
      if (p.pair_weights != 0u && pair_weight(e) == 0.0) continue;  // severed
      const vec3 x = (rest[j].xyz - xi) * inv_h;
      const float q = 1.0 - dot(x, x);
      if (q <= 0.0) continue;
      const float w = q * q * q;
      a[0] += w * x.x * x.x;
      a[1] += w * x.x * x.y;
      a[2] += w * x.x * x.z;
      a[3] += w * x.y * x.y;
      a[4] += w * x.y * x.z;
      a[5] += w * x.z * x.z;
      M += w * outerProduct((disp[j].xyz - ui) * inv_h, x);
    }
  }
  for (int c = 0; c < 6; ++c) partial_a[lid][c] = a[c];
  for (int c = 0; c < 3; ++c) partial_m[lid][c] = M[c];
  barrier();
  if (lane != 0 || k >= p.count) return;
  for (uint l = 1; l < kDeformLanes; ++l) {
    for (int c = 0; c < 6; ++c) a[c] += partial_a[lid + l][c];
    for (int c = 0; c < 3; ++c) M[c] += partial_m[lid + l][c];
  }
  const SurfelStatic s = surfels[k];
  Splat outp;
  if (!live) {  // a stale table entry: draw nothing
    outp.centre = vec4(0);
    outp.normal = vec4(0, 0, 1, 0);
    outp.ds_dx = vec4(0);
    outp.dt_dx = vec4(0);
    splats[k] = outp;
    return;
  }
  const vec3 xi = rest[i].xyz;
  const vec3 ui = disp[i].xyz;
  const mat3 A = mat3(a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]);
  const float tr = A[0][0] + A[1][1] + A[2][2];
  bool usable = tr > 0.0;
  mat3 f_inv_t = mat3(1.0);
  mat3 f = mat3(1.0);
  if (usable) {
    f = mat3(1.0) + M * regularised_inverse(A).inverse;
    const float det_f = determinant(f);
    usable = abs(det_f) > 1e-6;
    if (usable) f_inv_t = transpose(inverse(f));
  }
  if (!usable) f = mat3(1.0);

  const vec3 n0 = s.normal.xyz;
  vec3 n = f_inv_t * n0;
  const float len = length(n);
  n = usable && len > 0.0 ? n / len : n0;

  // Radius: grown by the largest tangential stretch (the square root of the larger eigenvalue
  // of the tangent-plane metric of F), so stretched surfaces stay closed; never shrunk.
  const vec3 t1 = any_tangent(n0);
  const vec3 t2 = cross(n0, t1);
  const vec3 a1 = f * t1;
  const vec3 a2 = f * t2;
  const float c11 = dot(a1, a1), c22 = dot(a2, a2), c12 = dot(a1, a2);
  const float half_diff = 0.5 * (c11 - c22);
  const float lambda = 0.5 * (c11 + c22) + sqrt(half_diff * half_diff + c12 * c12);
  const float stretch = clamp(sqrt(lambda), 1.0, p.max_stretch);

  const bool cut = (s.flags & kSurfelCutFace) != 0u;
  const bool torn = cut && (s.flags & kSurfelTornFace) != 0u;
  const vec3 offset = cut ? f * (n0 * s.normal.w) : vec3(0.0);
  outp.centre = vec4(xi + ui + offset, s.radius * stretch);
  const uint mirror = (s.flags >> kSurfelMirrorShift) & kMirrorLevels;
  outp.normal = vec4(n, float((usable ? kSplatUsable : 0u) | (cut ? kSplatCutFace : 0u) |
                              (torn ? kSplatTornFace : 0u) | (mirror << kSplatMirrorShift)));
  outp.ds_dx = vec4(f_inv_t * s.ds_dx.xyz, s.ds_dx.w);
  outp.dt_dx = vec4(f_inv_t * s.dt_dx.xyz, s.dt_dx.w);
  splats[k] = outp;
}
