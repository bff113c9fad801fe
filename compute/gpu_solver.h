// The GPU solver: the CPU reference's MLS physics (engine/solver/cpu_solver.h, docs/decisions.md)
// as Vulkan compute passes in float32, behind the engine's Solver interface.
//
//   construction  neighbour search on the GPU (hash grid, counting sort, CSR rows sorted by
//                 index), per-pair poly6 weights, moment matrices and their regularised
//                 inverses, hourglass stiffness, the forces of the initial state
//   advance(n)    n velocity-Verlet steps, recorded in submissions that grow from
//                 kFirstSubmitSteps to kStepsPerSubmit (two command buffers in flight: the
//                 next is recorded while the GPU runs the last); per step a stress pass (D_i) and a
//                 force pass (gather, half kick, and fused with the next step's half kick and
//                 drift), each over its pass list (CpuSolver's pass selection and sleeping:
//                 gpu_solver_passes.cpp); while principal stress is on (tearing), the stress pass
//                 also writes it
//   contact       with tools (set_tools), after every drift: the tools' correction of u and v
//                 over the chunk's candidate list, per-tool force samples by a fixed-order
//                 reduction (gpu_solver_contact.cpp; CpuSolver's semantics)
//   queries       energies (GPU pass + fixed-order reduction), first non-finite phyxel (GPU
//                 check), state download, von Mises stress (GPU pass)
//
// Buffers (compute/README.md, "GPU solver buffers", has the full list): everything per phyxel
// is a vec4 or a 32-bit word indexed by phyxel; everything per pair is aligned with the CSR
// neighbour index, so a pair or a phyxel can be deactivated in place (pair weight 0 on both
// sides, kRemoved in the flags word) and the precompute pass rerun for the phyxels it touches.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "compute/buffer.h"
#include "compute/context.h"
#include "compute/pair_buffer.h"
#include "compute/shaders/layout.h"
#include "compute/timing.h"
#include "engine/solver/check_prefetch.h"
#include "engine/solver/cut_band.h"
#include "engine/solver/solver.h"

namespace phyxel::gpu {

// What the renderer reads (valid for the solver's lifetime; contents change with advance()):
//   rest          vec4 per phyxel: x0.xyz (world, m), volume (m^3)
//   displacement  vec4 per phyxel: u.xyz (m), 0      (the state between advance() calls)
//   nbr_offset    uint[count + 1]  CSR row starts, as NeighbourLists::offset
//   nbr_index     uint[pairs]      CSR neighbour indices, as NeighbourLists::index
//   pair_weight   float[pairs]     the pair weights; 0: a severed or removed pair
// In a scene whose pairs exceed one binding, nbr_index and pair_weight hold the first
// nbr_index->size() / 4 pairs and nbr_index_hi and pair_weight_hi the rest (PairBuffer);
// otherwise the two are null.
struct SolverBuffers {
  const Buffer* rest;
  const Buffer* displacement;
  const Buffer* nbr_offset;
  const Buffer* nbr_index;
  uint32_t count;
  const Buffer* pair_weight;
  const Buffer* nbr_index_hi;
  const Buffer* pair_weight_hi;
};

struct GpuSolverOptions {
  // Where the step passes take w_ij from. Auto (default): recomputed from x0 (the same float
  // expression that filled the pair-weight buffer, so the same value), except for phyxels with
  // deactivated pairs (kFlagPairsEdited), which read the buffer (weight 0 marks a removed pair).
  // Stored: always the buffer. Auto moves 4 bytes less per pair and, more to the point, avoids a
  // second per-thread row of pair data striding through L1: 3.6x faster per step at 1M phyxels
  // on an H100 (docs/performance.md).
  enum class PairWeights { Auto, Stored };
  PairWeights pair_weights = PairWeights::Auto;
  // How the neighbour search tests |x0_j - x0_i|^2 < h^2 (1 - 1e-9): in double where the
  // device has shaderFloat64 (Auto, Float64: exactly the CPU's pairs), else in float against
  // h^2 (1 - 1e-5) (see compute/shaders/solver_nbr.glsl). Float64 throws without the feature.
  enum class SupportTest { Auto, Float64, Float32 };
  SupportTest support_test = SupportTest::Auto;
  // Invocations per phyxel in the gathering passes (stress, principal, force): 1, 2, 4, 8 or
  // 16 for all of them, or 0 (auto, GpuSolver::lanes_for): 1 on a CPU device (lavapipe);
  // on a GPU, for a small pass enough lanes that it has tens of thousands of invocations (a
  // small scene's pass is otherwise one thread walking ~25 neighbours one after another on a
  // mostly idle machine), and 2 for the force pass of a large one (more of its gathers in
  // flight). The sums are added in a fixed order, so a rerun is bit-identical; lanes > 1
  // changes the order of the neighbour sum, hence the last bits, against lanes = 1.
  uint32_t lanes = 0;
  // Bytes of pairs one part of the neighbour index and of the pair weights holds (PairBuffer):
  // 0, the device's limit (maxStorageBufferRange). Tests lower it to split a small scene's
  // pairs in two, as a scene past about 41M phyxels is.
  uint64_t pair_part_bytes = 0;
  // Phyxels per submission of the setup's passes (neighbour search, MLS precompute), which
  // poll the setup's stop (set_search_stop) before each: 0, sized from the measured rate to
  // about 20 ms of wall time each; tests fix it. Any size gives the same bits.
  uint32_t setup_chunk = 0;
  // While tearing with tools that only touch and suck (no blade, no grasper), or without
  // tearing where no blade has a threshold and at most one tool grasps: the tool contact after
  // each drift inside the force pass (solver_force_tear, solver_force_contact, the grasper's
  // hold too; substeps whose jaws close keep tool_contact) and the samples summed once after
  // the advance, as tool_contact gives them bit for bit. Tests turn it off to compare.
  bool contact_in_force = true;
  // With one grasper and tool_contact summing its own samples (no blade resisting): the hold of
  // its closed jaws inside tool_contact's dispatch, the same bits as its own pass after it.
  // Tests turn it off to compare.
  bool grasp_in_contact = true;
  // Where a blade resists (a threshold): tool_resist's last workgroup sums the samples and
  // empties the dirty list, in place of tool_contact_reduce's dispatch and the list's fill, the
  // same bits. Tests turn it off to compare.
  bool resist_reduce = true;
  // Where tool_contact would sum the samples and a sever follows that does not read them (no
  // blade with a threshold > 0): tool_contact_reduce sums them beside the sever, off the
  // substep's chain of dependent passes; the same bits. Tests turn it off to compare.
  bool sums_apart = true;
  // Cutting without tearing, band or principal stress: a substep's sever beside its stress pass
  // (no barrier between them; the sever's last workgroup redoes the stress of the phyxels it
  // cut pairs of once that pass is done), one dependent pass less a substep; the same bits.
  // Tests turn it off to compare. $PHYXEL_SEVER_BESIDE_STRESS "0" turns it off (GpuSolver's
  // constructor): for a driver that does not run the stress pass beside or before the sever,
  // where the sever's bounded wait runs out and the advance throws a VulkanError saying so.
  bool sever_beside_stress = true;
  // Only up to this many phyxels in the solver: beside the stress pass, the sever's last workgroup
  // redoes the stress of every phyxel it cut pairs of, which grows with the cut's face. H200,
  // breast_resection: +10 % at 10 579 phyxels, +1.3 % at 35 829, +1.7 % at 84 769, -5.8 % at
  // 165 565 (docs/performance.md).
  uint32_t sever_beside_max_phyxels = 100000;
  // Tests only, with sever_beside_stress: the sever recorded before its stress pass (a barrier
  // between), as a driver that ran it first would: its wait runs out, the advance throws.
  bool sever_before_stress = false;
};

// A^-1 of one phyxel as the GPU computed it (symmetric: xx xy xz yy yz zz).
struct MomentInverseRow {
  float inverse[6];
  bool regularised;
};

class SolverKernels;
struct GpuBand;

class GpuSolver final : public SolverWithAllFacets, public CheckPrefetch {
 public:
  static constexpr int64_t kStepsPerSubmit = 256;
  // An advance's first submission: the GPU starts after recording this many substeps, not the
  // whole advance (a tool chunk of 64 substeps cost the brain about 18 us of idle GPU per
  // substep while its host recorded; docs/performance-log.md, "Recording off the critical
  // path"). Each later one holds half the substeps recorded so far, up to kStepsPerSubmit.
  static constexpr int64_t kFirstSubmitSteps = 8;
  // Substeps of the submission after `done` substeps of an advance.
  static int64_t submit_steps(int64_t done) {
    return std::min(kStepsPerSubmit, std::max(kFirstSubmitSteps, done / 2));
  }
  // The host's side of the advances so far (phyxel bench --surgery --profile-parts): seconds
  // recording the substeps, submitting, waiting for the GPU, and the rest (the tools' motion
  // table and broad phase before, the samples and cut log read after); submissions and waits.
  struct AdvanceHostTimes {
    double record = 0, submit = 0, wait = 0, rest = 0;
    int64_t advances = 0, submissions = 0, waits = 0;
  };
  const AdvanceHostTimes& advance_host_times() const { return host_times_; }

  // Uses (does not own) `ctx`, which must outlive the solver.
  GpuSolver(Context& ctx, const PhyxelSet& set, const Vec3& gravity,
            const GpuSolverOptions& options = {});
  // Owns its context.
  GpuSolver(std::unique_ptr<Context> ctx, const PhyxelSet& set, const Vec3& gravity,
            const GpuSolverOptions& options = {});
  ~GpuSolver() override;
  GpuSolver(const GpuSolver&) = delete;
  GpuSolver& operator=(const GpuSolver&) = delete;

  // Solver.
  std::string device() const override;  // "gpu:0 NVIDIA H100 80GB HBM3 (float32)"
  // Returns once its last command buffer is submitted where the host has nothing left to do
  // for it (no tools, cutting or tearing); every other non-const member
  // waits for that submission first (settle()), and so does finish().
  void advance(int64_t substeps, double dt) override;
  // Each pause ends a submission; at(k) runs with buffers() showing u of substep k (which the
  // next submission's opening barrier keeps until at(k)'s work on the queue has read it).
  bool pauses_within_advance() const override { return true; }
  void advance_paused(int64_t substeps, double dt, const std::vector<int64_t>& pauses,
                      const std::function<void(int64_t)>& at) override;
  void finish() override { settle(); }
  bool advance_in_flight() const { return in_flight_ >= 0; }
  Energies energies() override;
  long first_non_finite() override;
  std::pair<double, double> max_norms() override;  // a GPU reduction; 16 bytes back
  std::vector<ObjectMotion> object_motion(const PhyxelSet& set) override;  // 16 bytes per object
  PointState read_state(bool with_stress) override;
  size_t regularised_count() const override { return regularised_; }
  const NeighbourLists& neighbours() const override { return neighbours_; }

  // Pass selection (on by default), sleeping and load changes, with exactly CpuSolver's
  // semantics (engine/solver/cpu_solver.h): the force pass and the kicks visit the phyxels that
  // move (not fixed, not removed, object awake), the stress pass those and their neighbours. Off:
  // every phyxel of an awake object that is not removed (fixed ones get their reactions and
  // never move). Each call rebuilds the pass lists on the host from the flags and the CSR,
  // uploads them and recomputes the forces.
  void set_pass_selection(bool enabled) override;
  bool pass_selection_on() const { return select_; }
  // Sleep (velocities zeroed on the GPU, every pass skipped) or wake an object.
  void set_object_awake(uint32_t object, bool awake) override;
  bool object_awake(uint32_t object) const { return awake_.at(object) != 0; }
  size_t stress_pass_size() const override { return stress_count_; }
  size_t force_pass_size() const override { return force_count_; }
  // Invocations per phyxel of a gathering pass over `count` phyxels (GpuSolverOptions::lanes).
  enum class Gather { Stress, Force };
  uint32_t lanes_for(Gather pass, uint32_t count) const;
  // Replaces the loads (per phyxel, N; gravity stays): ext = m g + load, uploaded, and the
  // forces recomputed for the current u.
  void set_external_forces(const std::vector<Vec3>& loads) override;
  // Tools, with CpuSolver's semantics (engine/solver/cpu_solver.h, engine/solver/contact.h):
  // contact runs after every drift on the phyxels the broad phase found for the chunk of
  // substeps whose motions set_tool_motion gave (kept for the next advance; a step past them
  // keeps the last end pose). At the start of an advance with new motions: max |u| and |v| by a
  // GPU reduction, the broad phase on the GPU (contact_candidates' twin: tool_broad_phase) and
  // the motion table uploaded, in the advance's command buffer. Sleeping or waking
  // (set_object_awake) runs the broad phase again at the next advance.
  // tool_samples(): what each tool felt in each substep of the last advance (substeps x
  // tools; read back once per advance). Without tools nothing is recorded.
  void set_tools(const std::vector<ContactTool>& tools) override;
  void set_tool_motion(const std::vector<ToolMotion>& motion) override;
  std::vector<ToolContactSample> tool_samples() override { return samples_; }
  size_t contact_candidates() const override { return candidates_; }
  bool blades_near() const override { return blades_near_; }  // tool_broad_scan's sever groups
  // Graspers, with CpuSolver's semantics (engine/solver/grasper.h): after each substep's
  // contact reduction, tool_grasp captures (in the substep the jaws close), holds and reduces
  // the grip's force into the sample (gpu_solver_grasp.cpp); nothing is read back during the
  // advance. held_phyxels downloads the grip.
  std::vector<uint32_t> held_phyxels(size_t tool) override;
  std::vector<Grip> grips() override;
  void restore_grips(const std::vector<Grip>& grips) override;
  // Principal stress (tearing), with CpuSolver's semantics (engine/solver/cpu_solver.h): while
  // on, every stress pass also writes it, from the same gather of grad u, into a float per
  // phyxel (allocated when first turned on, zeroed); read_state(true) downloads it.
  // Off (the default): the stress pass writes D only.
  void set_principal_stress(bool on) override;
  bool principal_stress_on() const { return principal_; }
  // Tearing, with CpuSolver's semantics (engine/solver/tearing.h): while on, the stress
  // pass also keeps each phyxel's Cauchy tensor, and the force pass of every substep is
  // solver_force_tear: the forces, then the tear test over the stress list (on the u the
  // stress pass read), its last workgroup rerunning the precompute of the phyxels it touched:
  // nothing is read back during the advance; the torn pairs come back with the cut log once per
  // advance.
  void set_tearing(bool on) override;
  // Cutting, with CpuSolver's semantics (engine/solver/cpu_solver.h): after each substep's
  // contact reduction, tool_sever over the candidates (dispatched indirectly) for every blade
  // whose edge force reached its threshold, then solver_precompute over the phyxels it touched
  // (indirectly, from the count the sever pass grew): nothing is read back during the advance.
  // The pairs it severed come back once per advance (a log in a Readback buffer, sorted on the
  // host; when it overflows, the pair weights are compared with the last known ones).
  size_t severed_pairs() const override { return severed_.size(); }
  std::vector<SeveredPair> severed_since(size_t first) override;
  std::vector<uint8_t> pair_alive() override;
  void sever_pairs(const std::vector<SeveredPair>& pairs) override;
  CutBandState cut_band_state() override;
  void restore_cut_band(const CutBandState& state) override;

  // The SCNI band (objects with cut_band > 0), with CpuSolver's semantics and moments
  // (engine/solver/cpu_solver.h; gpu_solver_band.cpp): the quads stored, the phyxels in it
  // (built or not), whether phyxel i's cell is integrated by it.
  const std::vector<std::array<Vec3, 4>>& cut_quads() const;
  size_t band_size() const;
  bool in_band(size_t i) const;
  // The blades' side entries (engine cutting.h side_entry) live on the device, written by
  // tool_sever; read back and written only for checkpoints.
  std::vector<std::vector<BladeSide>> blade_sides() override;
  void restore_blade_sides(const std::vector<std::vector<BladeSide>>& sides) override;
  std::vector<uint8_t> blades_cutting() override;
  void restore_blades_cutting(const std::vector<uint8_t>& on) override;

  Context& context() const { return *ctx_; }
  SolverBuffers buffers() const;
  size_t size() const { return count_; }
  uint64_t pair_count() const { return pairs_; }

  // Replaces u and v (uploads) and recomputes the forces for the new u.
  void set_state(const std::vector<Vec3>& displacement, const std::vector<Vec3>& velocity) override;
  // Recomputes the forces for the current u (as CpuSolver::compute_forces: the stress and
  // force passes over their lists).
  void compute_forces();
  // Total force per phyxel for the current u (download); as on the CPU, only the phyxels of
  // the force pass have one (the others keep their last, 0 until they were in it).
  std::vector<Vec3> forces();
  // The per-phyxel moment inverses and the per-pair weights (downloads, for tests).
  std::vector<MomentInverseRow> moment_inverses();
  std::vector<float> pair_weights();

  // Deactivates phyxels in place (what a cut does): flags them kRemoved, sets the weight of
  // every pair that touches them to 0 on both sides, flags their neighbours kFlagPairsEdited,
  // reruns the precompute pass for exactly those phyxels and recomputes the forces. A removed
  // phyxel keeps its u and v and no longer moves. The CSR (and neighbours()) is unchanged:
  // removed pairs stay in it with weight 0.
  void remove_phyxels(const std::vector<uint32_t>& ids) override;
  // Aspiration's reads (gpu_solver_near.cpp): solver_near selects the phyxels in the box (and
  // gathers by id) on the device; only those come back, written straight into read-back
  // buffers (20 bytes per phyxel that comes back, one submission).
  NearState read_near(const PhyxelSet& set, const Bounds& box) override;
  void prefetch_near(const Bounds& box) override;
  // first_non_finite and max_norms at the end of the next advance (gpu_solver_queries.cpp).
  void prefetch_checks() override { checks_asked_ = true; }
  // Whether first_non_finite and max_norms now come without a submission (tests).
  bool checks_prefetched() const { return checks_ready_; }
  // Whether the next read_near of the prefetched box comes without a submission (tests).
  bool near_prefetched() const { return near_ready_; }
  std::vector<Vec3> read_displacements(const std::vector<uint32_t>& ids) override;

  // Runs `steps` steps (>= 1) in one submit with a timestamp around every pass; returns the
  // median time per pass name ("kick_drift" once, then "stress" (with the principal stress
  // while on) and "force" per step ("force+tear" while tearing, after "tear: reset" where the
  // substep needs one), and "contact" after every drift while tools touch the candidates'
  // chunk). Empty where the device has no timestamps. Advances the state like advance(steps,
  // dt). per_dispatch: the contact and cut passes timed by their parts ("contact: tool", "cut:
  // sever", ...; a barrier counts with the part after it).
  std::vector<PassTime> profile(int64_t steps, double dt, bool per_dispatch = false);
  // Bytes each phyxel moves to and from device memory per step, as counted for the roofline
  // (per-phyxel and per-pair data read or written once per pass; a neighbour's data is counted
  // with its own phyxel, i.e. assumed to come from cache).
  double bytes_per_phyxel_step() const;

  // Device memory a set needs at most (persistent buffers plus the neighbour search's
  // temporaries), for Context::check_fits before anything is allocated. Assumes lattice
  // sampling (as sample_scene) to bound the pair count.
  static uint64_t required_device_bytes(const PhyxelSet& set);
  // The same for `phyxels` phyxels with `pairs` pairs in all (each counted from both sides),
  // before a set is sampled (phyxel bench refuses sizes the device cannot hold so). Throws
  // std::invalid_argument past what the neighbour search indexes.
  static uint64_t required_device_bytes(uint64_t phyxels, uint64_t pairs);
  // Whether `ctx` holds a solver of that many phyxels and pairs: its memory (check_fits) and
  // the largest buffer one binding reaches (maxStorageBufferRange: the stress, 48 bytes per
  // phyxel, at about 89M phyxels on NVIDIA; the neighbour index and the pair weights, 4 bytes
  // per pair, are bound in two parts, PairBuffer). Throws VulkanError naming the device, the
  // buffer and the bytes; std::invalid_argument past 2^31 phyxels.
  static void check_capacity(const Context& ctx, uint64_t phyxels, uint64_t pairs);

 private:
  void build(const PhyxelSet& set, const Vec3& gravity);
  void settle();          // waits for the submission advance() left in flight, if any
  void wait_in_flight();  // the same, keeping a prefetched read_near (host-only readers)
  void build_neighbours(const std::vector<layout::vec4>& rest_lo);
  // `record(rec, first, count)` over phyxels [0, count_), a submission per chunk, the stop
  // polled before each (SearchStopped naming `phase`).
  using ChunkRecorder = std::function<void(Recorder&, uint32_t first, uint32_t count)>;
  void run_in_chunks(Recorder& rec, const char* phase, const ChunkRecorder& record);
  void count_flags();                       // downloads the flags
  void count_flags(const uint32_t* flags);  // of count_ flags read back already
  void read_flags_and_weights(std::vector<uint32_t>& flags, std::vector<float>& weights);
  void build_pass_lists();  // host lists from flags, awake objects and CSR; uploads them
  void remove_from_pass_lists(const std::vector<uint32_t>& ids);  // the same, after a removal
  void upload_pass_lists();
  uint64_t stage_in_force_bits();
  bool in_stress(size_t i) const;
  void record_steps(Recorder& rec, int64_t from, int64_t to, int64_t total, float dt, int& cur,
                    PassTimer* timer);
  // A timestamp pair named `name` around what is recorded between them, while
  // profile(per_dispatch) runs.
  void part_begin(Recorder& rec, const char* name) {
    if (part_timer_) part_timer_->begin(rec, name);
  }
  void part_end(Recorder& rec) {
    if (part_timer_) part_timer_->end(rec);
  }
  // epoch != 0: the pass counts its workgroups as written (StressPush), for a sever beside it
  // that waits for the count `epoch`.
  void record_stress(Recorder& rec, const Buffer& disp, uint32_t epoch = 0);
  // The stress pass's workgroups; the count a sever beside the next one waits for (all the
  // advance's such passes, that one included); the count's reset, at an advance's start.
  uint64_t stress_groups() const;
  uint32_t count_stress_beside();
  void reset_stress_beside(Recorder& rec);
  // Whether substep `step`'s sever goes beside its stress pass (sever_beside_stress), in a
  // piece of the advance that ends before substep `to`.
  bool sever_beside(int64_t step, int64_t to) const;
  // solver_force_tear in place of record_force (gpu_solver_tearing.cpp).
  // contact_step >= 0: with the contact of that substep after the drift (contact_in_force_).
  void record_force_tear(Recorder& rec, uint32_t mode, float dt, const Buffer& in,
                         const Buffer& out, int64_t contact_step = -1);
  bool tear_needs_reset() const { return !contact_fused() || cutting_; }
  // The dirty list's header reset before tool_sever, which fills it.
  void record_dirty_reset(Recorder& rec);
  // The precompute pass over the phyxels of `list` (`elements` of them).
  void record_precompute(Recorder& rec, const layout::PrecomputePush& pc, const Buffer& list,
                         uint32_t elements);
  // A pass with solver_energy's bindings (energy, von Mises) over every phyxel, into `out`.
  void record_energy_like(Recorder& rec, const Pipeline& pass, const Buffer& out);
  void record_force(Recorder& rec, uint32_t mode, float dt, const Buffer& in, const Buffer& out);
  // count: the phyxels the pass visits (its list's length, or all of them).
  layout::StepPush push(uint32_t count, float dt, uint32_t mode = 0, uint32_t lanes = 1) const;
  // Contact (gpu_solver_contact.cpp). begin_contact: at the start of an advance of `substeps`,
  // the broad phase when new motions are pending; records the uploads into rec_[0] (not
  // submitted). record_contact: the contact and reduction passes after the drift of `step`.
  // finish_contact: the samples, once the advance's work is done (ran: the steps were run).
  void begin_contact(int64_t substeps, double dt);
  void record_contact(Recorder& rec, int64_t step, float dt, const Buffer& disp);
  // The contact push fields of substep `step`: its motion row, and 1 where it is past the
  // chunk's motions (the tools hold their last pose), else 0.
  uint32_t contact_motion_row(int64_t step) const;
  uint32_t contact_hold(int64_t step) const;
  // With contact_in_force_: the samples of substeps [first, end) from the force pass's rows.
  void record_contact_rows(Recorder& rec, int64_t first, int64_t end);
  // Without tearing (gpu_solver_force_contact.cpp): whether substep `step`'s contact may be the
  // force pass's (no jaws close in it); fuse_contact notes it as such and returns the grasper
  // whose hold the pass does; the pass; the grip's sum of that substep; the rows of each run.
  bool contact_fusable(int64_t step) const;
  uint32_t fuse_contact(int64_t step);
  void record_force_contact(Recorder& rec, float dt, const Buffer& in, const Buffer& out,
                            int64_t step, uint32_t grasp);
  void record_grip_row(Recorder& rec, int64_t step, uint32_t grasp);
  void record_fused_rows(Recorder& rec);
  void finish_contact(int64_t substeps, bool ran);
  void record_broad_phase(Recorder& rec);  // max norms, then the candidates and their count
  void record_max_norms(Recorder& rec);    // into max_norm_readback_
  // Cutting (gpu_solver_cutting.cpp): buffers for set_tools, the cut table of a new chunk,
  // the sever and precompute passes of a substep, the log after an advance.
  void prepare_cutting();
  void prepare_blade_sides();                    // set_tools: every blade's side entries, none kept
  uint64_t blade_state_word(size_t tool) const;  // its cutting state's word for the next pass
  uint32_t cut_pass(int64_t step) const;         // SeverPush.pass of a substep of the advance
  void upload_cut_quads(Recorder& rec);
  // stress_written != 0: recorded after that substep's stress pass with no barrier between
  // (sever_beside), which was recorded with that epoch (count_stress_beside).
  void record_sever(Recorder& rec, int64_t step, const Buffer& disp, uint32_t stress_written = 0);
  // The cut table's row of substep `step` of the advance (past the chunk: the held end pose).
  uint32_t cut_table_row(int64_t step) const;
  // tool_resist between tool_contact and its reduction, where a blade has a threshold.
  void record_resist(Recorder& rec, int64_t step, float dt, const Buffer& disp);
  // The cut log's header after an advance: the pairs cut or torn, and a VulkanError where a
  // sever beside the stress pass found that pass not run (kCutLogStressMissed).
  void finish_cutting();
  void take_cut_log(uint32_t found);  // the log's `found` pairs into severed_
  // Graspers (gpu_solver_grasp.cpp): the grip buffers for set_tools, and the capture, hold and
  // reduction passes of a substep, after the contact reduction.
  void prepare_grasping();
  // The grasper whose hold tool_contact does in this substep (layout ContactPush.grasp), or
  // kContactNoGrasp.
  uint32_t grasp_in_contact(int64_t step) const;
  // Forgets the grips of jaws that open in this substep; whether a grasper other than
  // `in_contact` has a pass to record.
  bool grasp_passes_left(int64_t step, uint32_t in_contact);
  void record_grasp(Recorder& rec, int64_t step, float dt, const Buffer& disp, uint32_t in_contact);
  // A host edit (remove_phyxels, sever_pairs): uploads the flags and weights and reruns the
  // precompute for the touched phyxels (ascending).
  void apply_edit(const std::vector<uint32_t>& flags, const std::vector<float>& weights,
                  const std::vector<uint32_t>& touched);
  void mark_severed(const SeveredPair& p);  // alive_ of both slots
  // The SCNI band (gpu_solver_band.cpp): made for a scene with cut_band; the quads of the last
  // advance's cuts; the cells built at a new chunk (all: every cell the quads reach), uploaded
  // with kFlagBand set on the phyxels that joined; the band's passes after the stress pass; the
  // ext the force pass reads (the band's copy once it has cells).
  void make_band(const PhyxelSet& set);
  void collect_band_quads();
  void refresh_band(bool all);
  void use_band(const CutBand::Refresh& refresh);  // uploads, flags, precompute, forces
  void upload_band();
  void copy_band_ext();  // ext into the band's copy (the nodes no box lists keep it)
  bool band_built() const;
  void record_band(Recorder& rec, const Buffer& disp);
  void record_band_stress(Recorder& rec, const Buffer& disp);
  double band_energy();  // sum V_b W(F_b) over the band's boxes, for the current u
  const Buffer& force_ext() const;
  std::unique_ptr<GpuBand> band_;
  bool contact_recorded() const { return contact_active_; }
  // tool_contact writes the samples itself (no tool_resist adds to its partials after it), and
  // the dirty list's empty header where there is one: the sever pass and the force pass's tear
  // test that follow it in the substep (without a sever between for the tear) need no reset of
  // their own.
  bool contact_fused() const { return contact_active_ && !resisting_; }
  // tool_resist sums the samples (and empties the dirty list) after tool_contact, which does not.
  bool resist_fused() const { return contact_active_ && resisting_ && options_.resist_reduce; }
  // The fuse bits of the pass that sums the samples (tool_contact or tool_resist): the sum, and
  // the dirty list emptied where there is one; 0 for a pass that does not.
  uint32_t sample_fuse(bool sums) const;
  // This advance's contact after substep 0 is in solver_force_tear (begin_contact decides).
  bool contact_in_force_ = false;
  // Its runs of substeps [first, end) whose contact the force pass did, and the grasper whose
  // grip rows (grip_rows_) leave their samples (kContactNoGrasp: none).
  std::vector<std::pair<int64_t, int64_t>> contact_runs_;
  uint32_t rows_grasp_ = 0xFFFFFFFFu;
  // The substep whose samples tool_contact left to record_sever's tool_contact_reduce (-1: none),
  // and the grasper whose grip's forces that pass subtracts (kContactNoGrasp: none).
  int64_t sums_pending_ = -1;
  uint32_t sums_grasp_ = 0xFFFFFFFFu;
  bool sample_in_sever_ = false;  // a blade with a threshold > 0: tool_sever reads the sample
  void record_sums_apart(Recorder& rec);

  std::unique_ptr<Context> owned_ctx_;
  Context* ctx_;
  GpuSolverOptions options_;
  std::unique_ptr<SolverKernels> kernels_;
  uint32_t count_ = 0;
  uint64_t pairs_ = 0;
  size_t regularised_ = 0;
  size_t edited_ = 0;  // phyxels flagged kFlagPairsEdited
  NeighbourLists neighbours_;

  // Per phyxel.
  Buffer classes_;        // SolverClass per (object, material)
  Buffer rest_;           // x0, volume
  Buffer local_;          // x0 - object centre (float), kappa
  Buffer disp_[2];        // u; disp_[0] holds it between advance() calls
  Buffer vel_;            // v
  Buffer force_;          // f for the u in disp_[0]
  Buffer ext_;            // m g + loads, m
  Buffer flags_;          // PhyxelFlags | kFlagRegularised | class << 16
  Buffer ainv_;           // 2 vec4
  Buffer resid_;          // 2 vec4
  Buffer stress_;         // D_i, 3 vec4 (w: u_i, as the stress pass read it)
  Buffer stress_done_;    // uint: the written workgroups of stress passes beside a sever
  Buffer nbr_offset_;     // N + 1
  PairBuffer nbr_index_;  // pairs, in two parts past one binding (pair_buffers.glsl)
  PairBuffer weight_;     // pairs
  Buffer energy_;         // per-phyxel energies, then the reduction levels
  Buffer reduce_[2];
  Buffer von_mises_;
  Buffer check_;
  Buffer list_;  // the precompute pass's phyxel list (remove_phyxels)
  // Persistent host-visible buffers of topology edits (gpu_solver_edit.cpp), on first use.
  Buffer edit_upload_, edit_readback_;
  Buffer list_upload_;  // the pass lists' upload (build_pass_lists), on first use
  // remove_phyxels' flag edits, pair slots and precompute list (Upload) and the flag counts
  // (Readback), on first use.
  Buffer removal_edits_, removal_slots_, removal_list_, removal_counts_;
  void apply_removal(const std::vector<uint32_t>& edits, const std::vector<uint32_t>& slots,
                     const std::vector<uint32_t>& touched);

  // Pass selection (gpu_solver_passes.cpp). Invariant between calls: every phyxel outside the
  // force list has the same u in both displacement buffers (compute_forces copies [0] to [1]),
  // so the step passes never need to write it.
  Vec3 gravity_;
  std::vector<uint32_t> phyxel_flags_;  // PhyxelFlags per phyxel (kRemoved kept up to date)
  std::vector<uint32_t> object_;        // object per phyxel
  std::vector<double> mass_;
  std::vector<ObjectRange> objects_;
  std::vector<uint8_t> awake_;  // per object
  bool select_ = true;
  size_t stress_count_ = 0, force_count_ = 0;
  // The pass lists on the host (ascending), membership of the force list, and per phyxel how
  // many force-list phyxels have it in their row (the stress pass's neighbourhood).
  std::vector<uint32_t> stress_list_host_, force_list_host_;
  // The stress list's phyxels not in the force list: uploaded after the force list, where
  // solver_force_tear tests their pairs.
  std::vector<uint32_t> tear_only_host_;
  std::vector<uint8_t> in_force_;
  std::vector<uint32_t> stress_refs_;
  AdvanceHostTimes host_times_;
  int shown_ = 0;  // the displacement buffer buffers() shows: 1 at some pauses of an advance
  int64_t substeps_run_ = 0;         // by advance(), over the solver's life (the device-loss hook)
  Buffer stress_list_, force_list_;  // uint phyxel indices, ascending, N capacity
  bool principal_ = false;           // set_principal_stress
  Buffer principal_stress_;          // float per phyxel, Pa (allocated when first on)
  bool tearing_ = false;             // set_tearing
  Buffer cauchy_;                    // vec4[2 N]: the Cauchy tensor (allocated when first on)

  // Tools (gpu_solver_contact.cpp); every buffer below is allocated by set_tools or grown
  // when a chunk needs more (never shrunk), so scenes without tools allocate none of it.
  std::vector<ContactTool> tools_;
  double contact_spacing_ = 0;                 // the largest object spacing (contact_margin)
  double chunk_duration_ = 0;                  // s: the motions' substeps times their dt
  std::vector<ToolMotion> pending_motion_;     // for the next advance
  std::vector<ToolMotion> motion_;             // the chunk's motions (substeps x tools)
  size_t motion_steps_ = 0, motion_step_ = 0;  // substeps in motion_, substeps consumed
  layout::vec4 contact_origin_{};           // the motion table's frame: rest bounds centre (float)
  bool broad_pending_ = false;              // the broad phase to run at the next advance
  size_t candidates_ = 0;                   // of the last advance (read with its samples)
  bool blades_near_ = false;                // its sever dispatched workgroups
  std::vector<ToolContactSample> samples_;  // of the last advance
  bool contact_active_ = false;             // contact passes recorded in this advance
  uint32_t candidate_capacity_ = 0;         // elements of the candidate buffers
  // Workgroups of tool_contact over candidate_capacity_ candidates (one partial sum each).
  uint32_t partial_capacity() const {
    return (std::max<uint32_t>(candidate_capacity_, 1) + PHYXEL_WORKGROUP_SIZE - 1) /
           PHYXEL_WORKGROUP_SIZE;
  }
  Buffer tool_shapes_;      // ContactToolShape per tool
  Buffer motion_table_;     // ContactMotion [substep][tool]; motion_upload_ stages it
  Buffer candidate_list_;   // uint[capacity]: the broad phase's phyxels, ascending
  Buffer contact_count_;    // Readback, indirect: ContactCount of the broad phase
  Buffer broad_groups_;     // uint per broad-phase workgroup: hits, then offsets
  Buffer candidate_force_;  // vec4[2 tools][partial_capacity()]: per workgroup, force and range
  Buffer contact_flag_;     // uint per phyxel: 1 where a tool touched it in the last substep
  Buffer contact_done_;     // uint: tool_contact's finished workgroups (kContactFuseReduce)
  Buffer candidate_slot_;   // uint per phyxel: its slot in candidate_list_, or ~0
  Buffer contact_rows_;     // vec4 [substep][2][tool][stride]: solver_force_tear's contact
  Buffer row_partials_;     // vec4 [substep][2][tool][partial_capacity()]: 64 rows' sums
  Buffer grip_rows_;        // vec4 [substep][tool][2] as the samples: the grip's sums (x of 2)
  Buffer in_force_bits_;    // a bit per phyxel: in the force list (in_force_)
  Buffer in_force_upload_;
  Buffer samples_buffer_;     // Readback: vec4 [substep][tool] (force on the tool, count)
  Buffer max_norm_readback_;  // Readback: (max |u|, max |v|, 0, 0)
  Buffer motion_readback_;    // Readback, per object: (kinetic energy, max |v|, 0, 0); made on use
  Buffer state_readback_;     // Readback for read_state (gpu_solver_queries.cpp), on first use
  struct StateLayout;
  void ensure_state_readback();
  // Records the copies of u (from disp_[0]) and the principal stress into state_readback_.
  void record_state_copies(Recorder& rec, bool velocity, bool von_mises, bool contact);
  Buffer motion_upload_;
  // read_near and read_displacements, made on first use: per solver_near workgroup its hits,
  // then offsets; the count (ContactCount); ids and (u, principal) per hit (Readback, room for
  // every phyxel); the ids of a gather (Upload).
  Buffer near_groups_, near_count_, near_ids_, near_state_, near_upload_;
  void ensure_near_buffers();
  void record_near(Recorder& rec, layout::NearPush push);
  // read_near's passes for `box` (selection, scan, gather into the read-back buffers).
  void record_near_box(Recorder& rec, const Bounds& box);
  // prefetch_near's box; asked for the next advance; recorded by the last one and nothing
  // since (settle() clears it: every call that touches the GPU starts with it).
  Bounds near_box_;
  bool near_asked_ = false, near_ready_ = false;
  // prefetch_checks: the check pass into check_ and the max norms into max_norm_readback_,
  // recorded after the last substep; valid until settle() (a read of the state keeps them).
  bool checks_asked_ = false, checks_ready_ = false;
  void record_check(Recorder& rec);   // first_non_finite's pass alone
  void record_checks(Recorder& rec);  // record_check, then record_max_norms
  // Waits for the advance in flight for a read that changes nothing on the device: the
  // prefetched checks stay, a prefetched read_near does not.
  void settle_for_read() {
    near_ready_ = false;
    wait_in_flight();
  }

  // Graspers (gpu_solver_grasp.cpp); allocated by set_tools only when a tool grasps.
  bool grasping_ = false;             // a tool grasps
  std::vector<uint8_t> grip_closed_;  // per tool: its jaws closed, as the passes recorded so far
  Buffer grip_;                       // GraspEntry [tool][count_]
  Buffer grip_count_;                 // ContactCount per tool (indirect)
  Buffer grip_force_;                 // vec4 [tool][count_]
  Buffer grip_of_;                    // uint [tool][count_]: a held phyxel's grip entry

  // Cutting (gpu_solver_cutting.cpp).
  bool cutting_ = false;                // a tool has a blade
  bool resisting_ = false;              // a blade has a threshold and an edge stiffness
  double max_support_ = 0;              // the largest support radius (the broad phase's margin)
  Buffer cut_quads_, cut_quad_upload_;  // CutQuad [row][tool]
  Buffer cut_dirty_;                    // uint: count, phyxels
  Buffer cut_done_;   // uint: finished workgroups of tool_sever or solver_force_tear; 0 between
  Buffer cut_log_;    // Readback: uvec4 (count, missed, 0, 0), then (i, j, t bits, torn)
  Buffer cut_sides_;  // uint [tool][phyxel]: side entries (tool_sever)
  uint32_t cut_pass_ = 0;  // substeps counted for them (SeverPush.pass)
  uint32_t log_capacity_ = 0;
  // What stress_done_ reaches at the advance's last stress pass beside a sever so far.
  uint64_t stress_beside_written_ = 0;
  // The smallest tear strength of any class that tears (+inf if none): ForceTearPush.weakest.
  float weakest_tear_ = std::numeric_limits<float>::infinity();
  std::vector<SeveredPair> severed_;  // the log (Solver::severed_since)
  std::vector<uint8_t> alive_;        // per pair, as the log says (overflow and pair_alive)

  std::unique_ptr<Recorder> rec_[2];
  PassTimer* part_timer_ = nullptr;  // profile(per_dispatch): the surgical passes' parts
  int in_flight_ = -1;               // the rec_ whose submission advance() left running, or -1
};

}  // namespace phyxel::gpu

namespace phyxel {

// The GPU solver with a context of its own (options.device picks the device). Throws
// VulkanError with one clear line when there is no loader, no device, or not enough memory.
std::unique_ptr<Solver> make_gpu_solver(const PhyxelSet& set, const Vec3& gravity,
                                        const gpu::ContextOptions& options,
                                        const gpu::GpuSolverOptions& solver_options = {});

}  // namespace phyxel
