#include "engine/solver/cpu_solver.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "engine/solver/kernel.h"
#include "engine/solver/suction.h"
#include "engine/solver/tearing.h"

namespace phyxel {
namespace {

// The quadrature volumes as the solver holds them (the band's boxes add up to them).
template <class Real>
std::vector<double> band_volumes(const PhyxelSet& set) {
  std::vector<double> v(set.volume.size());
  for (size_t i = 0; i < v.size(); ++i) v[i] = double(Real(set.volume[i]));
  return v;
}

}  // namespace

template <class Real>
CpuSolver<Real>::CpuSolver(const PhyxelSet& set, const Vec3& gravity)
    : gravity_(gravity),
      object_(set.object),
      awake_(set.objects.size(), 1),
      flags_(set.flags),
      nbr_(find_rest_neighbours(set)),
      band_(set, band_volumes<Real>(set)) {
  const size_t n = set.size();
  rest_.resize(n);
  mass_.resize(n);
  volume_.resize(n);
  damping_.resize(n);
  kappa_.resize(n);
  params_.resize(n);
  a_inv_.resize(n);
  a_residual_.resize(n);
  regularised_.assign(n, 0);
  no_fit_.assign(n, 0);
  external_.resize(n);
  w_.resize(nbr_.index.size());
  for (size_t i = 0; i < n; ++i) {
    rest_[i] = set.rest[i].cast<Real>();
    const Material& mat = set.materials[set.material[i]];
    mass_[i] = Real(set.mass[i]);
    volume_[i] = Real(set.volume[i]);
    damping_[i] = Real(mat.damping);
    const double kv = volume_stiffness(mat);
    params_[i] = {Real(lame_lambda(mat) - kv), Real(lame_mu(mat)), Real(kv)};
    external_[i] = (set.mass[i] * gravity + set.external_force[i]).cast<Real>();
  }
  tear_.resize(n);
  for (size_t i = 0; i < n; ++i)
    tear_[i] = Real(set.materials[set.material[i]].tear_stress.value_or(0.0));
  // Moment matrices, their regularised inverses and the pair weights (in double).
  support_.resize(set.objects.size());
  for (size_t o = 0; o < set.objects.size(); ++o) {
    support_[o] = set.objects[o].support_radius;
    max_support_ = std::max(max_support_, support_[o]);
  }
  kappa_scale_.resize(n);
  elastic_volume_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    // Hourglass stiffness: gamma mu v_i / (tr A_i / 3), so that the penalty energy of a
    // gradient error dG is about gamma/2 mu v_i |dG|^2, comparable to the elastic energy.
    const Material& mat = set.materials[set.material[i]];
    kappa_scale_[i] = mat.hourglass * lame_mu(mat) * set.volume[i];
    const double h = support_[object_[i]];
    for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k)
      w_[k] = Real(poly6((set.rest[nbr_.index[k]] - set.rest[i]).squaredNorm(), h));
  }
  rest_d_ = set.rest;
  size_t regularised = 0;
  // Polled as the search polls it (a precompute over many neighbours takes seconds too).
  std::atomic<bool> stopped{false};
#pragma omp parallel for schedule(dynamic, kSetupPollEvery) reduction(+ : regularised)
  for (size_t i = 0; i < n; ++i) {
    if (stopped.load(std::memory_order_relaxed)) continue;
    if (i % kSetupPollEvery == 0 && search_stop_requested()) {
      stopped.store(true, std::memory_order_relaxed);
      continue;
    }
    precompute(i);
    regularised += regularised_[i];
  }
  if (stopped.load()) throw SearchStopped("the MLS precompute");
  regularised_count_ = regularised;
  for (const ObjectRange& o : set.objects) contact_spacing_ = std::max(contact_spacing_, o.spacing);
  contact_.assign(n, 0);
  contact_force_.assign(n, V3::Zero());
  mass_d_ = set.mass;
  build_pass_lists();
  u_.assign(n, V3::Zero());
  v_.resize(n);
  for (size_t i = 0; i < n; ++i)
    v_[i] = (flags_[i] & kFixed) ? V3::Zero() : V3(set.initial_velocity[i].cast<Real>());
  f_.assign(n, V3::Zero());
  d_.assign(n, M3::Zero());
  compute_forces();
}

template <class Real>
void CpuSolver<Real>::precompute(size_t i) {
  // In double from the rest positions, over the pairs still alive (w != 0): exactly the
  // construction's values for an untouched phyxel.
  const double h = support_[object_[i]];
  // a: over the live pairs; reference: over every pair to a phyxel still in the physics (what
  // the phyxel's neighbourhood is without cuts and tears, as if sampled without the removed).
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero(), reference = Eigen::Matrix3d::Zero();
  bool damaged = false;  // a pair cut or torn (not lost to a removal): reference != a
  bool lost = false;     // a pair cut, torn or lost to a removal
  for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
    const uint32_t j = nbr_.index[k];
    const Vec3 x = rest_d_[j] - rest_d_[i];
    const Eigen::Matrix3d term = poly6(x.squaredNorm(), h) * x * x.transpose();
    if (!(flags_[j] & kRemoved)) reference += term;
    if (w_[k] != Real(0)) {
      a += term;
    } else {
      damaged = damaged || !(flags_[j] & kRemoved);
      lost = true;
    }
  }
  const MomentInverse inv = regularised_inverse(a);
  a_inv_[i] = inv.inverse.cast<Real>();
  a_residual_[i] = inv.residual.cast<Real>();
  regularised_[i] = inv.regularised;
  no_fit_[i] = left_without_fit(inv.regularised, lost, (flags_[i] & kFixed) != 0);
  // Damage: once pairs are cut or torn, the smallest eigenvalue of A_i falls and the
  // gradient's stiffest mode grows as 1/lambda_min, beyond what the stable step allows. The
  // phyxel's elastic response is scaled by lambda_min over the reference's, so no mode gets
  // stiffer (docs/tearing.md, "Damaged phyxels").
  const double damage =
      damaged ? damage_factor(min_moment_eigenvalue(a), min_moment_eigenvalue(reference)) : 1.0;
  elastic_volume_[i] = Real(damage * double(volume_[i]));
  const double tr = a.trace() / 3;
  kappa_[i] = tr > 0 && !in_band(i) ? Real(damage * kappa_scale_[i] / tr) : Real(0);
}

template <class Real>
int CpuSolver<Real>::threads_for(long n) const {
  // Below a few thousand phyxels a step takes well under a millisecond and the fork/join
  // barriers (several per step) cost more than they save, badly so when another process
  // holds a core: run such problems on one thread.
  constexpr long kMinPhyxelsPerThread = 1024;
  const int wanted = threads_ > 0 ? threads_ : omp_get_max_threads();
  return static_cast<int>(std::clamp<long>(n / kMinPhyxelsPerThread, 1, wanted));
}

template <class Real>
typename CpuSolver<Real>::M3 CpuSolver<Real>::moment_sum(size_t i) const {
  M3 m = M3::Zero();
  for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
    const uint32_t j = nbr_.index[k];
    m += w_[k] * (u_[j] - u_[i]) * (rest_[j] - rest_[i]).transpose();
  }
  return m;
}

template <class Real>
typename CpuSolver<Real>::M3 CpuSolver<Real>::gradient(size_t i) const {
  return moment_sum(i) * a_inv_[i];
}

template <class Real>
void CpuSolver<Real>::compute_forces() {
  const long ns = static_cast<long>(stress_list_.size());
  const long nf = static_cast<long>(force_list_.size());
  const int threads = threads_for(ns);
#pragma omp parallel num_threads(threads)
  {
#pragma omp for schedule(static)
    for (long s = 0; s < ns; ++s) {
      const uint32_t i = stress_list_[s];
      const M3 m = moment_sum(i);
      const M3 g = m * a_inv_[i];
      const M3 f = M3::Identity() + g;
      const M3 p = first_piola<Real>(f, params_[i], nullptr);
      M3 d = elastic_volume_[i] * p * a_inv_[i] - kappa_[i] * g;
      if (regularised_[i]) d += kappa_[i] * m * a_residual_[i];
      d_[i] = in_band(i) ? M3::Zero() : d;  // a band cell's energy is its boxes'

      if (tearing_) {
        const M3 sigma = phyxel::cauchy_stress<Real>(f, p);
        cauchy_[i] = Real(0.5) * (sigma + sigma.transpose());
        max_principal_[i] = symmetric_eigenvalues<Real>(cauchy_[i]).x();
      } else if (principal_) {
        max_principal_[i] = phyxel::max_principal_stress<Real>(f, p);
      }
    }
    const long nb = static_cast<long>(band_box_.size());
    if (nb > 0) {  // the same on every thread: no barrier without a band
#pragma omp for schedule(static)
      for (long c = 0; c < nb; ++c) band_stress(c);
    }
#pragma omp for schedule(static)
    for (long s = 0; s < nf; ++s) {
      const uint32_t k = force_list_[s];
      V3 force = external_[k];
      if (!band_.gather().empty()) force += band_force(k);
      for (uint32_t p = nbr_.offset[k]; p < nbr_.offset[k + 1]; ++p) {
        const uint32_t j = nbr_.index[p];
        const V3 x = rest_[j] - rest_[k];
        force += w_[p] * ((d_[k] + d_[j]) * x + (kappa_[k] + kappa_[j]) * (u_[j] - u_[k]));
      }
      f_[k] = force;
    }
  }
}

template <class Real>
void CpuSolver<Real>::build_pass_lists() {
  const size_t n = flags_.size();
  stress_list_.clear();
  force_list_.clear();
  std::vector<uint8_t> stress(n, 0);
  for (size_t i = 0; i < n; ++i) {
    if (!awake_[object_[i]] || (flags_[i] & kRemoved)) continue;
    // Without selection, fixed phyxels get forces too (reactions; they do not move).
    if (!select_ || !(flags_[i] & kFixed)) {
      force_list_.push_back(static_cast<uint32_t>(i));
      stress[i] = 1;
      if (select_)
        for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) stress[nbr_.index[k]] = 1;
    }
  }
  for (size_t i = 0; i < n; ++i)
    if (stress[i]) stress_list_.push_back(static_cast<uint32_t>(i));
}

template <class Real>
void CpuSolver<Real>::set_pass_selection(bool enabled) {
  select_ = enabled;
  build_pass_lists();
  compute_forces();
}

template <class Real>
void CpuSolver<Real>::set_object_awake(uint32_t object, bool awake) {
  if (bool(awake_[object]) == awake) return;
  awake_[object] = awake;
  if (!awake)
    for (size_t i = 0; i < v_.size(); ++i)
      if (object_[i] == object) v_[i] = V3::Zero();
  build_pass_lists();
  if (!motion_.empty()) find_candidates();  // the candidates follow the awake objects
  compute_forces();
}

template <class Real>
void CpuSolver<Real>::set_principal_stress(bool on) {
  if (on == principal_) return;
  principal_ = on;
  if (on) {
    max_principal_.assign(size(), Real(0));
    compute_forces();
  } else {
    max_principal_ = {};
    tearing_ = false;
    cauchy_ = {};
  }
}

template <class Real>
void CpuSolver<Real>::set_tearing(bool on) {
  if (on == tearing_) return;
  if (!on) {
    tearing_ = false;
    cauchy_ = {};
    return;
  }
  principal_ = true;
  tearing_ = true;
  max_principal_.assign(size(), Real(0));
  cauchy_.assign(size(), M3::Zero());
  compute_forces();
}

template <class Real>
void CpuSolver<Real>::set_external_forces(const std::vector<Vec3>& loads) {
  for (size_t i = 0; i < external_.size(); ++i)
    external_[i] = (mass_d_[i] * gravity_ + loads[i]).template cast<Real>();
  compute_forces();
}

template <class Real>
void CpuSolver<Real>::step(Real dt) {
  const long nf = static_cast<long>(force_list_.size());
  const Real half = dt / 2;
  const int threads = threads_for(nf);
  // The force list holds exactly the phyxels that move (when selection is off it also holds
  // fixed ones, which are skipped here).
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long s = 0; s < nf; ++s) {
    const uint32_t i = force_list_[s];
    if (flags_[i] & kFixed) continue;
    v_[i] = (v_[i] + half / mass_[i] * f_[i]) / (1 + damping_[i] * half);
    u_[i] += dt * v_[i];
  }
  if (!tools_.empty()) apply_contacts(dt);
  if (cutting_) apply_cuts();
  compute_forces();
  if (tearing_) apply_tears();
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long s = 0; s < nf; ++s) {
    const uint32_t i = force_list_[s];
    if (flags_[i] & kFixed) continue;
    v_[i] = (v_[i] + half / mass_[i] * f_[i]) / (1 + damping_[i] * half);
  }
}

template <class Real>
void CpuSolver<Real>::set_tools(const std::vector<ContactTool>& tools) {
  if (band_.on()) refresh_band();  // no blade left in the cut: all of it
  tools_ = tools;
  cutting_ = false;
  for (const ContactTool& t : tools_) cutting_ = cutting_ || t.blade.cuts();
  resisting_ = false;
  for (const ContactTool& t : tools_)
    resisting_ = resisting_ || (t.blade.cuts() && t.blade.threshold > 0 && t.blade.stiffness > 0);
  grasping_ = false;
  for (const ContactTool& t : tools_) grasping_ = grasping_ || t.grasp.grasps();
  grips_.assign(tools_.size(), Grip{});
  blade_side_.assign(cutting_ ? 2 * tools_.size() * size() : 0, 0u);
  blade_cutting_.assign(tools_.size(), 0);
  motion_.clear();
  motion_step_ = 0;
  candidates_.clear();
  blades_near_ = false;
  samples_.clear();
}

template <class Real>
void CpuSolver<Real>::set_tool_motion(const std::vector<ToolMotion>& motion, Real dt) {
  if (tools_.empty()) return;
  // The chunks before the last one: the cut has passed their cells.
  if (band_.on()) use_band(band_.start_chunk(flags_, threads_for(long(size()) * 256)));
  motion_ = motion;
  motion_step_ = 0;
  samples_.clear();
  chunk_duration_ = double(dt) * double(motion.size() / tools_.size());
  tool_speed_ = tool_speed(tools_, motion_, double(dt));
  find_candidates();
}

template <class Real>
void CpuSolver<Real>::find_candidates() {
  for (const uint32_t i : candidates_) {  // no stale contact from the last list
    contact_[i] = 0;
    contact_force_[i] = V3::Zero();
  }
  double max_v = 0;
  for (const V3& v : v_) max_v = std::max(max_v, double(v.norm()));
  const double reach = cut_candidate_reach(tools_, contact_spacing_, max_support_);
  const double margin = contact_margin(reach, max_v, tool_speed_, chunk_duration_);
  candidates_ = phyxel::contact_candidates<Real>(force_list_, flags_, rest_, u_,
                                                 swept_bounds(tools_, motion_), margin);
  // As tool_broad_scan: no sever without a candidate, nor at threshold 0 without one in reach.
  blades_near_ = !candidates_.empty() &&
                 (!blades_sever_in_reach_only(tools_) ||
                  !phyxel::contact_candidates<Real>(candidates_, flags_, rest_, u_,
                                                    blade_swept_bounds(tools_, motion_), margin)
                       .empty());
}

template <class Real>
void CpuSolver<Real>::apply_contacts(Real dt) {
  // This substep's motion of each tool; past the chunk's motions the tools stay at their
  // last end pose.
  const size_t nt = tools_.size();
  const size_t steps = motion_.size() / nt;
  std::vector<ToolMotion>& now = now_;
  now.assign(nt, ToolMotion{});
  for (size_t t = 0; t < nt; ++t) {
    if (steps == 0) return;
    const size_t k = std::min(motion_step_, steps - 1);
    now[t] = motion_[k * nt + t];
    if (motion_step_ >= steps) now[t].from = now[t].to;
  }
  ++motion_step_;
  for (size_t s = 0; s < candidates_.size(); ++s) {
    const uint32_t i = candidates_[s];
    contact_[i] = 0;
    contact_force_[i] = V3::Zero();
  }
  // In ascending phyxel order, tool by tool: the sums are the same on every run.
  std::vector<ToolContactSample> felt(nt);
  const std::vector<Vec3> side_normals = blade_side_normals();
  for (const uint32_t i : candidates_) {
    if (flags_[i] & kRemoved) continue;  // aspirated during the chunk
    for (size_t t = 0; t < nt; ++t) {
      const V3 x_new = rest_[i] + u_[i];
      const V3 x_prev = x_new - dt * v_[i];
      V3 dx, dv;
      const bool touches = contact_correction<Real>(tools_[t], now[t], dt, x_prev, x_new, v_[i], dx,
                                                    dv, kept_side(t, i, side_normals[t]));
      if (touches) {
        u_[i] += dx;
        v_[i] += dv;
        const V3 f = mass_[i] * dv / dt;
        contact_force_[i] += f;
        contact_[i] = 1;
        felt[t].force -= f.template cast<double>();
        ++felt[t].contacts;
      }
      if (now[t].suction_on) {  // the aspirator's pull (suction.h), after the contact
        const V3 x = rest_[i] + u_[i];
        const V3 tool_v = ((now[t].to.position - now[t].from.position) / double(dt)).cast<Real>();
        const V3 to_tip = (now[t].to.position.cast<Real>() - x).normalized();
        const V3 full = suction_pull<Real>(tools_[t], now[t].to, x, volume_[i]);
        const V3 pull =
            full * suction_flow_factor<Real>(tools_[t].suction, to_tip, V3(v_[i] - tool_v),
                                             dt / mass_[i] * full.norm());
        v_[i] += dt / mass_[i] * pull;
        felt[t].force -= pull.template cast<double>();
      }
      if (!touches && !tools_[t].blade.cuts()) continue;
      // Where it lies along the tool: in contact, or within a blade's band (ToolContactSample).
      const Vec3 x = (rest_[i] + u_[i]).template cast<double>();
      if (touches || tool_distance(tools_[t].shape, now[t].to, x).distance < contact_spacing_)
        felt[t].add_axial((x - now[t].to.position).dot(now[t].to.axis));
    }
  }
  if (resisting_) apply_edge_resistance(dt, felt);
  if (grasping_) apply_grasps(dt, now, felt);
  samples_.insert(samples_.end(), felt.begin(), felt.end());
}

template <class Real>
double CpuSolver<Real>::internal_energy() const {
  const long n = static_cast<long>(size());
  double total = 0;
#pragma omp parallel for schedule(static) reduction(+ : total)
  for (long i = 0; i < n; ++i) {
    const M3 g = gradient(i);
    Real w_density = 0;
    first_piola<Real>(M3::Identity() + g, params_[i], &w_density);
    Real hourglass = 0;
    for (uint32_t k = nbr_.offset[i]; k < nbr_.offset[i + 1]; ++k) {
      const uint32_t j = nbr_.index[k];
      const V3 e = g * (rest_[j] - rest_[i]) - (u_[j] - u_[i]);
      hourglass += w_[k] * e.squaredNorm();
    }
    const double elastic = in_band(i) ? 0.0 : double(elastic_volume_[i] * w_density);
    total += elastic + 0.5 * double(kappa_[i] * hourglass);
  }
  for (long c = 0; c < static_cast<long>(band_box_.size()); ++c) total += band_energy(c);
  return total;
}

template <class Real>
Energies CpuSolver<Real>::energies() const {
  Energies e;
  e.strain = internal_energy();
  for (size_t i = 0; i < size(); ++i) {
    e.kinetic += 0.5 * double(mass_[i]) * double(v_[i].squaredNorm());
    e.potential -= double(external_[i].dot(u_[i]));
  }
  return e;
}

template <class Real>
std::vector<double> CpuSolver<Real>::von_mises_stress() const {
  std::vector<double> out(size());
#pragma omp parallel for schedule(static)
  for (long i = 0; i < static_cast<long>(size()); ++i) {
    const M3 f = M3::Identity() + gradient(i);
    out[i] = double(von_mises<Real>(f, first_piola<Real>(f, params_[i], nullptr)));
  }
  return out;
}

template <class Real>
long CpuSolver<Real>::first_non_finite() const {
  for (size_t i = 0; i < size(); ++i)
    if (!u_[i].allFinite() || !v_[i].allFinite()) return static_cast<long>(i);
  return -1;
}

template class CpuSolver<double>;
template class CpuSolver<float>;

}  // namespace phyxel
