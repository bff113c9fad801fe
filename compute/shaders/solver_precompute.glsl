// The precompute of one phyxel (solver_precompute's; the last workgroup of tool_sever and of
// solver_force_tear runs it over the dirty list, pair_edit.glsl): from the stored pair
// weights, the moment matrix A_i = sum_j w_ij x_ij x_ij^T,
// its inverse through a symmetric eigen-decomposition (cyclic Jacobi), regularised when the
// condition number exceeds kMaxCondition (small eigenvalues raised to lambda_max / 100), the
// residual R_i = A^-1 A A^-1 - A^-1 of a regularised inverse, and the hourglass stiffness
// kappa_i = gamma mu v_i / (tr A_i / 3), both scaled by the phyxel's damage. The inverse is
// moment_inverse.glsl's (engine/solver/mls_model.h's twin). Idempotent, so cutting can rerun it
// for the phyxels it touched. Include after the buffers offset, local_pos, flags, classes, rest,
// ainv and resid and pair_buffers.glsl (pair_weight).
#ifndef PHYXEL_SOLVER_PRECOMPUTE_GLSL
#define PHYXEL_SOLVER_PRECOMPUTE_GLSL

#include "moment_inverse.glsl"
#include "solver_mls.glsl"

// The sums over a phyxel's pairs: a over the live pairs; reference over every pair to a phyxel
// not removed (for the damage); damaged: a pair cut or torn (not lost to a removal).
struct PairMoments {
  mat3 a;
  mat3 reference;
  bool damaged;
};

// Adds the pair at x from the phyxel (stored weight w; removed: the other side's kFlagRemoved).
void add_pair_moment(inout PairMoments m, vec3 x, float w, bool removed, vec4 kernel) {
  const mat3 term = outerProduct(w * x, x);
  m.a += term;
  if (!removed) {
    m.damaged = m.damaged || w == 0.0;
    m.reference += w != 0.0 ? term : outerProduct(poly6_weight(dot(x, x), kernel) * x, x);
  }
}

// From the sums: the inverse, residual, damage, kappa and flags of phyxel i (flags fl).
// cut_list: i came from a dirty list, whose kFlagCutDirty it clears.
void finish_precompute(uint i, uint fl, SolverClass cls, PairMoments m, bool cut_list) {
  const mat3 a = m.a;
  const float trace = a[0][0] + a[1][1] + a[2][2];
  const MomentInverse moment = regularised_inverse(a);
  const float lmin = moment.lambda_min;
  const mat3 inv = moment.inverse;
  const mat3 residual = moment.residual;
  const bool regularised = moment.regularised;
  // Damage (engine/solver/mls_model.h damage_factor): the elastic volume and kappa scaled by
  // lambda_min over the reference's; exactly 1, without a second eigen-decomposition, until a
  // cut or a tear took one of its pairs.
  float damage = 1.0;
  if (m.damaged) {
    mat3 q_reference;
    const vec3 lr = jacobi_eigen(m.reference, q_reference);
    const float reference_lmin = min(lr.x, min(lr.y, lr.z));
    damage = reference_lmin > 0.0 ? clamp(lmin / reference_lmin, 0.0, 1.0)
                                  : (lmin >= reference_lmin ? 1.0 : 0.0);
  }
  const float volume = (fl & kFlagBand) != 0u ? 0.0 : damage * rest[i].w;
  local_pos[i].w = trace > 0.0 ? cls.kernel.z * cls.elastic.y * volume / (trace / 3.0) : 0.0;
  ainv[2u * i] = vec4(inv[0][0], inv[1][0], inv[2][0], inv[1][1]);
  ainv[2u * i + 1u] = vec4(inv[2][1], inv[2][2], volume, 0.0);
  resid[2u * i] = vec4(residual[0][0], residual[1][0], residual[2][0], residual[1][1]);
  resid[2u * i + 1u] = vec4(residual[2][1], residual[2][2], 0.0, 0.0);
  const uint kept = cut_list ? (fl & ~kFlagCutDirty) : fl;
  // tearing.h left_without_fit (kFlagPairsEdited: a pair of it was cut, torn or removed).
  const bool no_fit = regularised && (fl & kFlagPairsEdited) != 0u && (fl & kFlagFixed) == 0u;
  flags[i] = (kept & ~(kFlagRegularised | kFlagNoFit)) | (regularised ? kFlagRegularised : 0u) |
             (no_fit ? kFlagNoFit : 0u);
}

void precompute_phyxel(uint i, bool cut_list) {
  const vec3 xi = local_pos[i].xyz;
  const uint fl = flags[i];
  const SolverClass cls = classes[fl >> kFlagClassShift];
  PairMoments m = PairMoments(mat3(0.0), mat3(0.0), false);
  for (uint k = offset[i]; k < offset[i + 1u]; ++k) {
    const uint j = nbr_index(k);
    add_pair_moment(m, local_pos[j].xyz - xi, pair_weight(k), (flags[j] & kFlagRemoved) != 0u,
                    cls.kernel);
  }
  finish_precompute(i, fl, cls, m, cut_list);
}

#endif  // PHYXEL_SOLVER_PRECOMPUTE_GLSL
