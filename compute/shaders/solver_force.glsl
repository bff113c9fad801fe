// Step pass 2, per phyxel k of the force pass list (a gather by p.lanes invocations, no
// atomics):
//   f_k = ext_k + sum_j w_kj [ (D_k + D_j) x_kj + (kappa_k + kappa_j) (u_j - u_k) ]
// then, by mode: nothing more (kForceOnly); the closing half kick of this step (kForceKick);
// or that kick, the next step's opening half kick and its drift into disp_out
// (kForceKickDrift; disp_in is read by neighbours in this pass, so u goes to the other buffer).
// Included by solver_force.comp and, with PHYXEL_FORCE_TEARS defined, by solver_force_tear.comp
// (the tear test fused after it): there the weights are uint bits the pass may clear, the
// flags and kappa (local_pos.w) are written by its last workgroup's precompute, and with
// kForceContact the tool contact follows the drift (force_contact.glsl); and with
// PHYXEL_FORCE_CONTACT by solver_force_contact: the contact and the grasper's hold, no tear.
#ifndef PHYXEL_SOLVER_FORCE_GLSL
#define PHYXEL_SOLVER_FORCE_GLSL

#include "solver_mls.glsl"

layout(local_size_x = PHYXEL_WORKGROUP_SIZE) in;

#if defined(PHYXEL_FORCE_TEARS) || defined(PHYXEL_FORCE_CONTACT)
layout(push_constant) uniform Push { ForceTearPush p; };
#endif
#ifdef PHYXEL_FORCE_TEARS
#define PHYXEL_FORCE_LOCAL
#define PHYXEL_FORCE_FLAGS coherent
#define PHYXEL_PAIR_ACCESS 2
#define PHYXEL_PAIR_WEIGHT_COHERENT
#else
#ifndef PHYXEL_FORCE_CONTACT
layout(push_constant) uniform Push { StepPush p; };
#endif
#define PHYXEL_FORCE_LOCAL readonly
#define PHYXEL_FORCE_FLAGS readonly
#define PHYXEL_PAIR_ACCESS 0
#endif
layout(std430, binding = kForceBindingOffset) readonly buffer Offset { uint offset[]; };
#define PHYXEL_PAIR_INDEX_BINDING kForceBindingIndex
#define PHYXEL_PAIR_INDEX_HI_BINDING kForceBindingIndexHi
#define PHYXEL_PAIR_WEIGHT_BINDING kForceBindingWeight
#define PHYXEL_PAIR_WEIGHT_HI_BINDING kForceBindingWeightHi
#include "pair_buffers.glsl"
layout(std430, binding = kForceBindingLocal) PHYXEL_FORCE_LOCAL buffer Local { vec4 local_pos[]; };
layout(std430, binding = kForceBindingDispIn) readonly buffer DispIn { vec4 disp_in[]; };
layout(std430, binding = kForceBindingDispOut) writeonly buffer DispOut { vec4 disp_out[]; };
layout(std430, binding = kForceBindingStress) readonly buffer Stress { vec4 stress[]; };
layout(std430, binding = kForceBindingVel) buffer Vel { vec4 vel[]; };
layout(std430, binding = kForceBindingForce) writeonly buffer Force { vec4 force[]; };
layout(std430, binding = kForceBindingExt) readonly buffer Ext { vec4 ext[]; };
layout(std430, binding = kForceBindingFlags) PHYXEL_FORCE_FLAGS buffer Flags { uint flags[]; };
layout(std430, binding = kForceBindingClasses) readonly buffer Classes { SolverClass classes[]; };
layout(std430, binding = kForceBindingList) readonly buffer List { uint pass_list[]; };
#if defined(PHYXEL_FORCE_TEARS) || defined(PHYXEL_FORCE_CONTACT)
#include "force_contact.glsl"
#endif

mat3 stress_of(uint i) {
  return mat3(stress[3u * i].xyz, stress[3u * i + 1u].xyz, stress[3u * i + 2u].xyz);
}

// D_j and u_j of a neighbour from its three stress columns (solver_stress stores u_j, which it
// read from disp_in, in their fourth components): one gather fewer per pair.
void stress_and_disp(uint j, out mat3 d, out vec3 u) {
  const vec4 c0 = stress[3u * j], c1 = stress[3u * j + 1u], c2 = stress[3u * j + 2u];
  d = mat3(c0.xyz, c1.xyz, c2.xyz);
  u = vec3(c0.w, c1.w, c2.w);
}

// Lane q of a phyxel's lanes sums neighbours q, q + lanes, ...; lane 0 (which starts from the
// external force) then adds the lanes' sums in lane order, so reruns are bit-identical.
shared vec3 partial_f[PHYXEL_WORKGROUP_SIZE];

// Every invocation of the workgroup calls it (its barrier).
void force_pass(uint invocation) {
  const uint lanes = p.lanes;
  const uint slot = invocation / lanes;
  const uint lane = invocation % lanes;
  const bool in_pass = slot < p.count;
  uint k = 0u, fl = 0u;
  SolverClass cls;
  vec3 uk = vec3(0.0);
  vec4 e = vec4(0.0);
  vec3 f = vec3(0.0);
  if (in_pass) {
    k = pass_list[slot];
    fl = flags[k];
    cls = classes[fl >> kFlagClassShift];
    const vec4 lk = local_pos[k];
    uk = disp_in[k].xyz;
    const mat3 dk = stress_of(k);
    e = ext[k];
    const bool stored = stored_weights(p.weights, fl);
    if (lane == 0u) f = e.xyz;
    const uint end = offset[k + 1u];
    // Two neighbours per iteration, their loads issued before either is used (more gathers in
    // flight per invocation); added in the same order as one at a time. The next iteration's
    // two indices are loaded before this one's gathers, so they are in flight meanwhile.
    uint s = offset[k] + lane;
    uint n0 = s < end ? nbr_index(s) : 0u;
    uint n1 = s + lanes < end ? nbr_index(s + lanes) : 0u;
    for (; s + lanes < end; s += 2u * lanes) {
      const uint j0 = n0;
      const uint j1 = n1;
      if (s + 2u * lanes < end) n0 = nbr_index(s + 2u * lanes);
      if (s + 3u * lanes < end) n1 = nbr_index(s + 3u * lanes);
      const vec4 l0 = local_pos[j0];
      const vec4 l1 = local_pos[j1];
      mat3 d0, d1;
      vec3 u0, u1;
      stress_and_disp(j0, d0, u0);
      stress_and_disp(j1, d1, u1);
      const vec3 x0 = l0.xyz - lk.xyz;
      const vec3 x1 = l1.xyz - lk.xyz;
      const float w0 = stored ? pair_weight(s) : poly6_weight(dot(x0, x0), cls.kernel);
      const float w1 = stored ? pair_weight(s + lanes) : poly6_weight(dot(x1, x1), cls.kernel);
      f += w0 * ((dk + d0) * x0 + (lk.w + l0.w) * (u0 - uk));
      f += w1 * ((dk + d1) * x1 + (lk.w + l1.w) * (u1 - uk));
    }
    if (s < end) {
      const uint j = n0;
      const vec4 lj = local_pos[j];
      const vec3 x = lj.xyz - lk.xyz;
      const float w = stored ? pair_weight(s) : poly6_weight(dot(x, x), cls.kernel);
      mat3 dj;
      vec3 uj;
      stress_and_disp(j, dj, uj);
      f += w * ((dk + dj) * x + (lk.w + lj.w) * (uj - uk));
    }
  }
  if (lanes > 1u) {  // uniform: every invocation of the workgroup reaches the barrier
    partial_f[gl_LocalInvocationIndex] = f;
    barrier();
    if (lane != 0u || !in_pass) return;
    for (uint q = 1u; q < lanes; ++q) f += partial_f[gl_LocalInvocationIndex + q];
  }
  if (!in_pass) return;
  force[k] = vec4(f, 0.0);
  if (p.mode == kForceOnly) return;
  if (!moves(fl)) {
#ifdef PHYXEL_FORCE_CONTACT
    vec3 v_held = vel[k].xyz;  // a fixed phyxel in the list may be held (no contact)
    if ((p.contact_fuse & kForceContact) != 0u && force_hold(k, fl, e.w, uk, v_held))
      vel[k] = vec4(v_held, 0.0);
#endif
    if (p.mode == kForceKickDrift) disp_out[k] = vec4(uk, 0.0);
    return;
  }
  const float half_dt = 0.5 * p.dt;
  const float damping = cls.elastic.w;
  vec3 v = half_kick(vel[k].xyz, f, e.w, damping, half_dt);
  if (p.mode == kForceKickDrift) {
    v = half_kick(v, f, e.w, damping, half_dt);
    vec3 u_next = drift(uk, v, p.dt);
#if defined(PHYXEL_FORCE_TEARS) || defined(PHYXEL_FORCE_CONTACT)
    if ((p.contact_fuse & kForceContact) != 0u) force_contact(k, fl, e.w, u_next, v);
#endif
#ifdef PHYXEL_FORCE_CONTACT
    if ((p.contact_fuse & kForceContact) != 0u) force_hold(k, fl, e.w, u_next, v);
#endif
    disp_out[k] = vec4(u_next, 0.0);
  }
  vel[k] = vec4(v, 0.0);
}

#endif  // PHYXEL_SOLVER_FORCE_GLSL
