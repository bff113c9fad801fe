// The CPU reference solver: meshless MLS elasticity (DESIGN.md section 3), templated on the
// scalar type (double is the reference; float mirrors the GPU's precision).
//
// Per step, in two gather passes over the symmetric rest neighbour lists:
//  1. per phyxel i: M_i = sum_j w_ij (u_j - u_i) x_ij^T, grad u_i = M_i A_i^-1, F = I + grad u,
//     P_i (St Venant-Kirchhoff + volume term), and
//     D_i = v_i P_i A_i^-1 + kappa_i M_i R_i - kappa_i grad u_i
//  2. per phyxel k: f_k = sum_j w_kj [ (D_k + D_j) x_kj + (kappa_k + kappa_j) (u_j - u_k) ]
// which is exactly -dU/du_k of U = sum_i v_i W(F_i) + kappa_i/2 sum_j w_ij |e_ij|^2, with the
// hourglass residual e_ij = grad u_i x_ij - (u_j - u_i) (docs/decisions.md derives it).
// No float atomics, no scatter: results do not depend on the thread count.
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "engine/sampling/phyxel_set.h"
#include "engine/solver/contact.h"
#include "engine/solver/cut_band.h"
#include "engine/solver/cutting.h"
#include "engine/solver/grasper.h"
#include "engine/solver/mls_model.h"
#include "engine/solver/neighbours.h"

namespace phyxel {

struct Energies {
  double kinetic = 0;    // sum 1/2 m |v|^2
  double strain = 0;     // elastic + volume + hourglass
  double potential = 0;  // of gravity and constant loads: -sum (m g + f_ext) . u
  double total() const { return kinetic + strain + potential; }
};

template <class Real>
class CpuSolver {
 public:
  using V3 = Eigen::Matrix<Real, 3, 1>;
  using M3 = Eigen::Matrix<Real, 3, 3>;

  CpuSolver(const PhyxelSet& set, const Vec3& gravity);

  size_t size() const { return u_.size(); }
  void set_threads(int threads) { threads_ = threads; }

  std::vector<V3>& displacement() { return u_; }
  std::vector<V3>& velocity() { return v_; }
  const std::vector<V3>& displacement() const { return u_; }
  const std::vector<V3>& velocity() const { return v_; }
  // Total force on each phyxel (internal + gravity + loads) for the current displacement.
  const std::vector<V3>& force() const { return f_; }
  const NeighbourLists& neighbours() const { return nbr_; }
  size_t regularised_count() const { return regularised_count_; }

  // Pass selection (on by default): the force pass runs only for phyxels that move, and the
  // stress pass only for those and their neighbours; fixed-only regions cost nothing. Sleeping
  // objects are skipped entirely. Off: every pass runs over every phyxel (--no-skip).
  void set_pass_selection(bool enabled);
  bool pass_selection() const { return select_; }
  // Sleep (velocities zeroed, all passes skipped) or wake an object.
  void set_object_awake(uint32_t object, bool awake);
  bool object_awake(uint32_t object) const { return awake_[object] != 0; }
  // Replaces the loads (per phyxel, N; gravity stays) and recomputes the forces.
  void set_external_forces(const std::vector<Vec3>& loads);
  // Phyxels in the stress and force passes now.
  size_t stress_pass_size() const { return stress_list_.size(); }
  size_t force_pass_size() const { return force_list_.size(); }

  // Tools (engine/solver/contact.h): contact runs after every drift, on the phyxels the broad
  // phase found for the chunk of substeps whose motions set_tool_motion gave (substeps x
  // tools, consumed one substep per step(); a step past them keeps the last end pose). The
  // broad phase runs again when an object falls asleep or wakes.
  void set_tools(const std::vector<ContactTool>& tools);
  void set_tool_motion(const std::vector<ToolMotion>& motion, Real dt);
  // What each tool felt per substep since set_tool_motion (substeps x tools).
  const std::vector<ToolContactSample>& tool_samples() const { return samples_; }
  // 1 where a tool touched the phyxel in the last step.
  const std::vector<uint8_t>& contact() const { return contact_; }
  // The contact force on each phyxel in the last step (N; zero where there was no contact).
  const std::vector<V3>& contact_force() const { return contact_force_; }
  size_t contact_candidates() const { return candidates_.size(); }
  // Whether the cut pass tests pairs in this chunk: the last broad phase found candidates and,
  // where every blade cuts at threshold 0, one within the blades' reach
  // (blades_sever_in_reach_only).
  bool blades_near() const { return blades_near_; }
  // Graspers (engine/solver/grasper.h): after the contacts of every step, each grasper whose
  // jaws close in the step captures the candidates within its reach, and each closed grasper
  // carries what it holds (cpu_solver_grasp.cpp). The grip of tool t (empty for other tools).
  const Grip& grip(size_t tool) const { return grips_.at(tool); }
  const std::vector<Grip>& grips() const { return grips_; }
  // Puts checkpointed grips back (after set_tools): one per tool, phyxels in range.
  void restore_grips(const std::vector<Grip>& grips);

  // Cutting (engine/solver/cutting.h, docs/cutting.md): after the contacts of every step, each
  // scalpel whose edge force reached its threshold severs the pairs that cross the quad its
  // blade swept (tested from the broad phase's candidates, whose margin grows by the support
  // radius when a tool cuts). A severed pair gets weight 0 on both sides, for good; the moment
  // matrices, inverses and hourglass stiffness of its two phyxels are recomputed from their
  // remaining pairs before the forces. A phyxel left without pairs moves as a free particle.
  // Every pair severed so far (i < j), in the order found; sort_severed_from(k) sorts the
  // entries from k on by (i, j).
  const std::vector<SeveredPair>& severed_log() const { return severed_; }
  void sort_severed_from(size_t first);
  size_t severed_count() const { return severed_.size(); }
  // w_ij aligned with neighbours().index (0: severed).
  const std::vector<Real>& pair_weights() const { return w_; }
  // Severs the pairs (i, j) given (both sides; a pair not in the lists is refused) and
  // recomputes what they touch, as a cut would (checkpoint resume, tests).
  void sever_pairs(const std::vector<SeveredPair>& pairs);
  // The sides each blade keeps after the last substep (cutting.h, BladeSide); restore puts
  // them back (after set_tools).
  size_t tool_count() const { return tools_.size(); }
  std::vector<BladeSide> blade_sides(size_t tool) const;
  void restore_blade_sides(size_t tool, const std::vector<BladeSide>& sides);
  // Whether the tool's blade is in the cutting state (docs/cutting.md, "Rupture and the cutting
  // state"): it passed its threshold and has advanced through tissue in every substep since.
  bool blade_cutting(size_t tool) const;
  void restore_blade_cutting(size_t tool, bool on);

  // Takes the phyxels out of the physics (Solver::remove_phyxels): flags them kRemoved, sets
  // the weight of every pair touching them to 0 on both sides, reruns the precompute of their
  // neighbours, rebuilds the pass lists and recomputes the forces. Throws std::out_of_range for
  // an index outside the set.
  void remove_phyxels(const std::vector<uint32_t>& ids);

  // Recomputes force() from the current displacement; call after changing u by hand.
  void compute_forces();
  // One velocity-Verlet (leapfrog) step of size dt with implicit mass-proportional damping.
  void step(Real dt);

  Energies energies() const;
  // Elastic + volume + hourglass energy only, for finite-difference checks.
  double internal_energy() const;
  // Displacement gradient of phyxel i for the current displacement.
  M3 gradient(size_t i) const;
  // Von Mises equivalent of the Cauchy stress per phyxel.
  std::vector<double> von_mises_stress() const;
  // Principal stress (for tearing; off by default): while on, the stress pass also computes
  // the largest principal value of each phyxel's Cauchy stress (mls_model.h) from the F and P
  // it has anyway, so it is current for the u of every compute_forces() and step(). Phyxels
  // outside the stress pass keep their last value (0 until they were in it): fixed-only ones
  // are unstressed, sleeping ones have not moved. Turning it on computes it at once.
  void set_principal_stress(bool on);
  bool principal_stress() const { return principal_; }
  // Pa per phyxel; empty while off.
  const std::vector<Real>& max_principal_stress() const { return max_principal_; }
  // Tearing (engine/solver/tearing.h, docs/tearing.md; off by default): while on, every step
  // ends by severing the live pairs whose material is overstressed (pair_tears on the Cauchy
  // stress the stress pass keeps per phyxel), logged with `torn` set in severed_log(). Turning
  // it on turns the principal stress on; phyxels whose material has no tear_stress never tear.
  void set_tearing(bool on);
  bool tearing() const { return tearing_; }
  // The symmetrised Cauchy stress per phyxel as the last stress pass left it; empty while off.
  const std::vector<M3>& cauchy_stress() const { return cauchy_; }
  // Index of the first phyxel with a non-finite displacement or velocity, or -1.
  long first_non_finite() const;

  // The SCNI band (objects with cut_band > 0; cpu_solver_band.cpp, docs/cutting.md "Stiffness
  // of a cut body"): the quads the blades swept while cutting such an object are kept, and the
  // phyxels within cut_band spacings of them take smoothed strains on 2^3 sub-boxes of their
  // cells (scni_band.h) instead of their nodal gradient, damage and hourglass term. The cells
  // are built when the cut has passed them (no quad of the last chunk within h + s: at each
  // set_tool_motion) and at set_tools (or refresh_band) for all. Until then a phyxel keeps the
  // nodal scheme.
  const std::vector<std::array<Vec3, 4>>& cut_quads() const { return band_.quads(); }
  size_t band_size() const { return band_.cells().size(); }  // phyxels in it (built or not)
  // Whether phyxel i's cell is integrated by the band (built at least once).
  bool in_band(size_t i) const { return band_.in_band(i); }
  CutBandState cut_band_state() const { return band_.state(); }
  void restore_cut_band(const CutBandState& state) {
    use_band(band_.restore(state, flags_, threads_for(long(size()) * 256)));
  }
  void refresh_band() { use_band(band_.refresh_all(flags_, threads_for(long(size()) * 256))); }

 private:
  M3 moment_sum(size_t i) const;  // M_i
  int threads_for(long n) const;  // threads worth using for n phyxels
  void build_pass_lists();
  void apply_contacts(Real dt);  // after the drift of step()
  void find_candidates();        // the chunk's broad phase (contact_candidates)
  void apply_cuts();             // after apply_contacts (cpu_solver_cutting.cpp)
  // In apply_contacts, after the contacts: the pairs each blade's edge holds push back on it
  // (cutting.h, EdgeFrame), into v and `felt` (cpu_solver_cutting.cpp).
  void apply_edge_resistance(Real dt, std::vector<ToolContactSample>& felt);
  EdgeFrame substep_edge(size_t tool) const;  // this substep's (stiffness 0: holds nothing)
  Vec3 held_pairs_force(uint32_t i, const EdgeFrame& edge, size_t tool, double band) const;
  // Phyxel i's (at x) kept side for the tool in pass `pass`, lapsed where stale (cutting.h,
  // side_near_plane).
  uint32_t side_held(size_t tool, uint32_t i, const Vec3& x, const EdgeFrame& edge, uint32_t pass,
                     double band) const;
  void cut_with_blade(size_t tool, std::vector<uint32_t>& touched);  // apply_cuts, one blade
  // Per tool, this substep's blade plane normal where it keeps sides (else zero); phyxel i's
  // side of it for the contact (contact_correction's keep).
  std::vector<Vec3> blade_side_normals() const;
  Vec3 kept_side(size_t tool, uint32_t i, const Vec3& normal) const;
  double plane_crossings(uint32_t i, const Vec3& normal) const;  // S_i (pair_area_share)
  // In apply_contacts, after the contacts: the graspers' capture, hold and release, their
  // forces and held counts into `felt` (cpu_solver_grasp.cpp).
  void apply_grasps(Real dt, const std::vector<ToolMotion>& now,
                    std::vector<ToolContactSample>& felt);
  void apply_tears();         // after the stress pass of step() (cpu_solver_tearing.cpp)
  void precompute(size_t i);  // A_i^-1, its residual, kappa_i from the live pairs of i
  bool sever(uint32_t i, uint32_t k, float t);  // pair k of row i; false if already severed
  // The band (cpu_solver_band.cpp): the cells CutBand built, in Real; their hourglass off.
  void use_band(const CutBand::Refresh& refresh);
  void band_stress(long cell);          // the boxes' V_b P_b (compute_forces)
  V3 band_force(uint32_t k) const;      // on phyxel k from the band cells listing it
  double band_energy(long cell) const;  // sum V_b W(F_b)
  M3 box_gradient(long cell, size_t box) const;
  void precompute_touched(std::vector<uint32_t>& touched);  // sorted, deduplicated, rerun

  Vec3 gravity_;
  std::vector<uint32_t> object_;
  std::vector<uint8_t> awake_;  // per object
  bool select_ = true;
  std::vector<uint32_t> stress_list_, force_list_;  // phyxels each pass visits

  std::vector<uint32_t> flags_;
  std::vector<V3> rest_;
  std::vector<Real> mass_, volume_, damping_, kappa_;
  // The volume whose elastic energy a phyxel carries: v_i, times its damage factor once cuts or
  // tears took some of its pairs (precompute; docs/tearing.md "Damaged phyxels").
  std::vector<Real> elastic_volume_;
  std::vector<ElasticParams<Real>> params_;
  std::vector<M3> a_inv_, a_residual_;
  std::vector<uint8_t> regularised_;
  // left_without_fit (tearing.h): its pairs tear at the next tear pass.
  std::vector<uint8_t> no_fit_;
  std::vector<V3> external_;  // m g + loads
  std::vector<double> mass_d_;
  NeighbourLists nbr_;
  std::vector<Real> w_;  // w_ij aligned with nbr_.index
  size_t regularised_count_ = 0;
  int threads_ = 0;

  // Tools.
  std::vector<ContactTool> tools_;
  double contact_spacing_ = 0;  // the largest object spacing, for contact_margin
  double chunk_duration_ = 0;   // s: the motions' substeps times their dt
  double tool_speed_ = 0;       // m/s: the fastest point of a tool over the motions
  std::vector<ToolMotion> motion_;
  size_t motion_step_ = 0;  // substeps of motion_ consumed
  std::vector<uint32_t> candidates_;
  bool blades_near_ = false;  // a candidate within the blades' reach (find_candidates)
  std::vector<ToolContactSample> samples_;
  std::vector<uint8_t> contact_;
  std::vector<V3> contact_force_;
  std::vector<ToolMotion> now_;  // this substep's motion of each tool (apply_contacts)
  bool grasping_ = false;        // a tool grasps
  std::vector<Grip> grips_;      // per tool

  // Cutting.
  bool cutting_ = false;              // a tool has a blade
  bool resisting_ = false;            // a blade has a threshold and an edge stiffness
  double max_support_ = 0;            // the largest support radius (the broad phase's margin)
  std::vector<double> support_;       // per object
  std::vector<Vec3> rest_d_;          // x0 in double (the precompute's input)
  std::vector<double> kappa_scale_;   // gamma mu v_i: kappa_i = kappa_scale_i / (tr A_i / 3)
  std::vector<SeveredPair> severed_;  // the log
  // [tool][phyxel] side entries (cutting.h, side_entry), then [tool][phyxel] the normals they
  // were learned on (pack_side_normal), as the GPU's side buffer.
  std::vector<uint32_t> blade_side_;
  uint32_t cut_pass_ = 0;               // substeps counted for the side entries
  std::vector<uint8_t> blade_cutting_;  // per tool: in the cutting state

  // The SCNI band: its cells and quads (double), and the boxes in Real with their stress.
  struct BandBox {
    Real volume = 0;
    std::vector<V3> coeff;   // G = sum u_node c^T (the nodes: band_'s)
    M3 stress = M3::Zero();  // V_b P_b
  };
  CutBand band_;
  std::vector<std::vector<BandBox>> band_box_;  // per cell

  std::vector<V3> u_, v_, f_;
  std::vector<M3> d_;  // pass-1 result

  bool principal_ = false;
  std::vector<Real> max_principal_;  // N while principal_, else empty

  // Tearing.
  bool tearing_ = false;
  std::vector<Real> tear_;  // per phyxel: its material's tear_stress, Pa (0: never tears)
  std::vector<M3> cauchy_;  // per phyxel while tearing_: the symmetrised Cauchy stress
};

extern template class CpuSolver<double>;
extern template class CpuSolver<float>;

}  // namespace phyxel
