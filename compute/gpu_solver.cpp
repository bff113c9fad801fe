// GpuSolver: construction, the step recording of advance(), state upload and the Solver
// interface plumbing. The neighbour search and precompute are in gpu_solver_neighbours.cpp,
// the downloads and GPU queries in gpu_solver_queries.cpp.
#include "compute/gpu_solver.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "compute/env.h"
#include "compute/gpu_solver_band.h"
#include "compute/gpu_solver_kernels.h"
#include "compute/gpu_solver_setup.h"

namespace phyxel::gpu {

using namespace layout;

namespace {

// A buffer bound as one storage-buffer range must fit maxStorageBufferRange.
void check_binding_size(const Context& ctx, uint64_t bytes, const char* what) {
  const uint64_t limit = ctx.info().max_storage_buffer_range;
  if (bytes <= limit) return;
  throw VulkanError(std::string("the scene needs a ") + what + " buffer of " + format_bytes(bytes) +
                        " but " + ctx.info().name + " binds at most " + format_bytes(limit) +
                        " (maxStorageBufferRange); use a smaller scene, "
                        "or --device cpu",
                    VK_ERROR_OUT_OF_DEVICE_MEMORY);
}

std::vector<vec4> to_vec4(const std::vector<Vec3>& x) {
  std::vector<vec4> out(x.size());
  for (size_t i = 0; i < x.size(); ++i)
    out[i] = {float(x[i].x()), float(x[i].y()), float(x[i].z()), 0.0f};
  return out;
}

}  // namespace

uint64_t GpuSolver::required_device_bytes(const PhyxelSet& set) {
  return required_device_bytes(set.size(), lattice_pair_bound(set));
}

uint64_t GpuSolver::required_device_bytes(uint64_t n, uint64_t pairs) {
  const uint64_t buckets = hash_buckets(n);
  // Scan levels and reduction levels hold about 1/256 of their input each; allocation
  // granularity is covered by a page per buffer (about 40 buffers).
  const uint64_t small = 2 * (n + buckets) * sizeof(uint32_t) / (kScanBlock - 1) + 2 * 16 * n / 255;
  return n * (kPersistentBytesPerPhyxel + kSearchBytesPerPhyxel) + pairs * kBytesPerPair +
         buckets * kSearchBytesPerBucket + small + 64 * 4096;
}

void GpuSolver::check_capacity(const Context& ctx, uint64_t phyxels, uint64_t pairs) {
  if (phyxels >= (uint64_t{1} << 31))
    throw std::invalid_argument("the GPU solver indexes phyxels with 31 bits");
  ctx.check_fits(required_device_bytes(phyxels, pairs));
  check_binding_size(ctx, phyxels * 48, "stress (48 bytes per phyxel)");
  // The neighbour index and the pair weights are bound in two parts (PairBuffer).
  const uint64_t per_part = pairs_per_part(ctx);
  if (pairs > 2 * per_part)
    throw VulkanError("the scene needs a neighbour index (4 bytes per pair) of " +
                          format_bytes(pairs * 4) + " but " + ctx.info().name + " binds at most " +
                          format_bytes(2 * per_part * 4) +
                          " of it (two bindings of maxStorageBufferRange); use a smaller "
                          "scene, or --device cpu",
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
}

namespace {

// The options with the environment's say: $PHYXEL_SEVER_BESIDE_STRESS "0" turns
// sever_beside_stress off (a malformed value is a VulkanError, as the context's variables).
GpuSolverOptions with_env(GpuSolverOptions options) {
  try {
    options.sever_beside_stress =
        options.sever_beside_stress && env_switch("PHYXEL_SEVER_BESIDE_STRESS");
  } catch (const EnvError& e) {
    throw VulkanError(e.what());
  }
  return options;
}

}  // namespace

GpuSolver::GpuSolver(Context& ctx, const PhyxelSet& set, const Vec3& gravity,
                     const GpuSolverOptions& options)
    : ctx_(&ctx), options_(with_env(options)) {
  build(set, gravity);
}

GpuSolver::GpuSolver(std::unique_ptr<Context> ctx, const PhyxelSet& set, const Vec3& gravity,
                     const GpuSolverOptions& options)
    : owned_ctx_(std::move(ctx)), ctx_(owned_ctx_.get()), options_(with_env(options)) {
  if (ctx_ == nullptr) throw std::invalid_argument("GpuSolver: no context");
  build(set, gravity);
}

GpuSolver::~GpuSolver() {
  try {
    settle();
  } catch (...) {
    // A lost device: nothing is left to wait for.
  }
  band_.reset();  // its buffers and pipelines before the context it may own
}

void GpuSolver::settle() {
  near_ready_ = false;  // a prefetched read_near is for the call right after its advance
  checks_ready_ = false;
  wait_in_flight();
}

void GpuSolver::wait_in_flight() {
  if (in_flight_ < 0) return;
  const int k = in_flight_;
  in_flight_ = -1;  // waited for once, even where the wait throws
  rec_[k]->wait();
}

void GpuSolver::build(const PhyxelSet& set, const Vec3& gravity) {
  if (set.size() >= (size_t{1} << 31))
    throw std::invalid_argument("the GPU solver indexes phyxels with 31 bits");
  count_ = static_cast<uint32_t>(set.size());
  const uint32_t lanes = options_.lanes;
  if (lanes > kMaxLanes || (lanes & (lanes - 1)) != 0)
    throw std::invalid_argument("GPU solver lanes must be 0 (auto), 1, 2, 4, 8 or 16, not " +
                                std::to_string(lanes));
  // Everything this set needs, before the first allocation: one clear error with the bytes.
  check_capacity(*ctx_, count_, lattice_pair_bound(set));

  const SolverSetup host = prepare_solver_setup(set, gravity);
  // Pipelines for pairs in two parts where the lattice bound says one may not hold them.
  const uint64_t per_part = pairs_per_part(*ctx_, options_.pair_part_bytes);
  kernels_ = std::make_unique<SolverKernels>(*ctx_, lattice_pair_bound(set) > per_part,
                                             static_cast<uint32_t>(per_part));
  Context& ctx = *ctx_;
  const uint64_t n = count_;
  auto device = [&](uint64_t bytes, const char* name) {
    return Buffer(ctx, bytes, MemoryIntent::Device, name);
  };
  classes_ = device(host.classes.size() * sizeof(SolverClass), "solver classes");
  rest_ = device(n * sizeof(vec4), "rest (x0, volume)");
  local_ = device(n * sizeof(vec4), "local rest (x0 - centre, kappa)");
  disp_[0] = device(n * sizeof(vec4), "displacement");
  disp_[1] = device(n * sizeof(vec4), "displacement (next)");
  vel_ = device(n * sizeof(vec4), "velocity");
  force_ = device(n * sizeof(vec4), "force");
  ext_ = device(n * sizeof(vec4), "external force, mass");
  flags_ = device(n * sizeof(uint32_t), "flags");
  ainv_ = device(2 * n * sizeof(vec4), "moment inverse");
  resid_ = device(2 * n * sizeof(vec4), "moment residual");
  stress_ = device(3 * n * sizeof(vec4), "stress D");
  stress_done_ = device(sizeof(uint32_t), "stress workgroups written beside a sever");
  upload(ctx, stress_done_, std::vector<uint32_t>(1, 0u));
  nbr_offset_ = device((n + 1) * sizeof(uint32_t), "neighbour offsets");
  energy_ = device(n * sizeof(vec4), "energy per phyxel");
  const uint64_t level1 = (n + kScanBlock - 1) / kScanBlock;
  reduce_[0] = device(level1 * sizeof(vec4), "energy partial sums");
  reduce_[1] =
      device(((level1 + kScanBlock - 1) / kScanBlock) * sizeof(vec4), "energy partial sums (next)");
  von_mises_ = device(n * sizeof(float), "von Mises stress");
  // Host-visible: the run loop's checks read them every few steps without a staging copy.
  check_ = Buffer(ctx, sizeof(uint32_t), MemoryIntent::Readback, "non-finite check");
  max_norm_readback_ = Buffer(ctx, sizeof(vec4), MemoryIntent::Readback, "max |u|, |v|");
  list_ = device(sizeof(uint32_t), "precompute list");
  stress_list_ = device(std::max<uint64_t>(n, 1) * sizeof(uint32_t), "stress pass list");
  force_list_ = device(std::max<uint64_t>(n, 1) * sizeof(uint32_t), "force pass list");
  gravity_ = gravity;
  phyxel_flags_ = set.flags;
  object_ = set.object;
  mass_ = set.mass;
  objects_ = set.objects;
  awake_.assign(set.objects.size(), 1);
  for (const ObjectRange& o : set.objects) {
    contact_spacing_ = std::max(contact_spacing_, o.spacing);
    max_support_ = std::max(max_support_, o.support_radius);
  }
  {
    // The contact frame: tools work on the tissue, so positions relative to its centre keep
    // the per-substep motion's precision in float; the same for the solver's life.
    Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    for (const Vec3& x : set.rest) {
      lo = lo.cwiseMin(x);
      hi = hi.cwiseMax(x);
    }
    const Vec3 centre = set.rest.empty() ? Vec3::Zero() : Vec3(0.5 * (lo + hi));
    contact_origin_ = {float(centre.x()), float(centre.y()), float(centre.z()), 0.0f};
  }

  upload(ctx, classes_, host.classes);
  for (const SolverClass& c : host.classes)  // the tear test's bound (solver_force_tear.comp)
    if (c.search.w > 0 && std::isfinite(c.search.w))
      weakest_tear_ = std::min(weakest_tear_, c.search.w);
  upload(ctx, rest_, host.rest);
  upload(ctx, local_, host.local);
  upload(ctx, ext_, host.ext);
  upload(ctx, vel_, host.velocity);
  upload(ctx, flags_, host.flags);
  {
    Recorder rec(ctx, "solver init");
    rec.fill(disp_[0], 0);
    rec.fill(disp_[1], 0);
    rec.fill(list_, 0);
    rec.fill(force_, 0);  // as the CPU's: 0 until a phyxel is in the force pass
    // The force pass reads D_j and u_j of every neighbour from here, with weight 0 where j was
    // removed before any stress pass visited it: finite, never garbage.
    rec.fill(stress_, 0);
    rec.submit_and_wait();
  }
  build_neighbours(host.rest_lo);  // CSR, weights, A^-1, kappa; then the first forces
  build_pass_lists();
  make_band(set);
  for (int k = 0; k < 2; ++k)
    rec_[k] = std::make_unique<Recorder>(ctx, k == 0 ? "solver steps A" : "solver steps B");
  compute_forces();
}

std::string GpuSolver::device() const {
  const DeviceInfo& info = ctx_->info();
  return "gpu:" + std::to_string(info.index) + " " + info.name + " (float32)";
}

SolverBuffers GpuSolver::buffers() const {
  return {&rest_, &disp_[shown_],       &nbr_offset_,           &nbr_index_.lo_buffer(),
          count_, &weight_.lo_buffer(), nbr_index_.hi_buffer(), weight_.hi_buffer()};
}

StepPush GpuSolver::push(uint32_t count, float dt, uint32_t mode, uint32_t lanes) const {
  return {count, dt, mode,
          options_.pair_weights == GpuSolverOptions::PairWeights::Stored ? kWeightsStored
                                                                         : kWeightsAuto,
          lanes};
}

// Auto, from the H100's per-pass timestamps at 5k-1M phyxels (docs/performance-log.md, "Small
// scenes"): a pass of a few thousand phyxels is latency-bound (each thread walks ~25
// neighbours one after another), so it gets lanes up to about 32k (stress) or 64k (force)
// invocations; at 100k both are fastest with one lane (the set lives in L2); from 256k the
// force pass, which gathers D_j (48 B) per pair from DRAM, is 1.6x faster with two.
uint32_t GpuSolver::lanes_for(Gather pass, uint32_t count) const {
  uint32_t lanes = options_.lanes;
  if (lanes == 0) {
    lanes = 1;
    if (ctx_->info().type != VK_PHYSICAL_DEVICE_TYPE_CPU) {
      const uint64_t target = pass == Gather::Stress ? 32768 : 65536;
      const uint32_t most = pass == Gather::Stress ? 8 : kMaxLanes;
      while (lanes < most && uint64_t{count} * lanes < target) lanes *= 2;
      if (pass == Gather::Force && count >= 262144) lanes = 2;
    }
  }
  // A dispatch counts its invocations in 32 bits.
  while (lanes > 1 && uint64_t{count} * lanes > UINT32_MAX) lanes /= 2;
  return lanes;
}

// With the principal stress on, the same gather also writes it (and the tensor while tearing);
// buffers not written are bound by stand-ins of the right kind.
void GpuSolver::record_stress(Recorder& rec, const Buffer& disp, uint32_t epoch) {
  const uint32_t n = static_cast<uint32_t>(stress_count_);
  const uint32_t mode = !principal_ ? kStressOnly
                        : tearing_  ? kStressWithTensor
                                    : kStressWithPrincipal;
  const StressPush pc{push(n, 0.0f, mode, lanes_for(Gather::Stress, n)), epoch};
  const Buffer& principal = principal_ ? principal_stress_ : von_mises_;
  dispatch(rec, kernels_->stress, pc,
           {{"Offset", nbr_offset_},
            {"IndexLo", nbr_index_.lo()},
            {"WeightLo", weight_.lo()},
            {"Local", local_},
            {"Disp", disp},
            {"Ainv", ainv_},
            {"Resid", resid_},
            {"Flags", flags_},
            {"Classes", classes_},
            {"Stress", stress_},
            {"List", stress_list_},
            {"Principal", principal},
            {"Cauchy", tearing_ ? cauchy_ : energy_},
            {"IndexHi", nbr_index_.hi()},
            {"WeightHi", weight_.hi()},
            {"Done", stress_done_}},
           n * pc.step.lanes);
  record_band(rec, disp);  // while the band has cells
}

void GpuSolver::record_force(Recorder& rec, uint32_t mode, float dt, const Buffer& in,
                             const Buffer& out) {
  const uint32_t n = static_cast<uint32_t>(force_count_);
  const StepPush pc = push(n, dt, mode, lanes_for(Gather::Force, n));
  dispatch(rec, kernels_->force, pc,
           {{"Offset", nbr_offset_},
            {"IndexLo", nbr_index_.lo()},
            {"WeightLo", weight_.lo()},
            {"Local", local_},
            {"DispIn", in},
            {"DispOut", out},
            {"Stress", stress_},
            {"Vel", vel_},
            {"Force", force_},
            {"Ext", force_ext()},
            {"Flags", flags_},
            {"Classes", classes_},
            {"List", force_list_},
            {"IndexHi", nbr_index_.hi()},
            {"WeightHi", weight_.hi()}},
           n * pc.lanes);
}

// Steps [from, to) of an advance of `total` steps. u lives in disp_[cur]. The first step opens
// with the kick-drift pass; every step but the last closes with the force pass fused with the
// next step's kick and drift, which writes u into the other buffer (its neighbours still read
// the current one), and the last closes with the plain half kick. The opening pass writes
// in place or into the other buffer so that the u of the last step lands in disp_[0]. With
// tools in reach, the contact passes follow every drift, on the buffer it wrote.
void GpuSolver::record_steps(Recorder& rec, int64_t from, int64_t to, int64_t total, float dt,
                             int& cur, PassTimer* timer) {
  auto timed = [&](const char* name, auto&& record) {
    // With part_timer_ the surgical passes time their parts themselves; the step passes (the
    // fused force and tear test among them) and the tear's reset are one part each.
    const bool whole =
        timer && !(part_timer_ && std::strncmp(name, "stress", 6) != 0 &&
                   std::strncmp(name, "force", 5) != 0 && std::strcmp(name, "kick_drift") != 0 &&
                   std::strcmp(name, "tear: reset") != 0);
    if (whole) timer->begin(rec, name);
    record();
    if (whole) timer->end(rec);
    rec.barrier();
  };
  int64_t beside = -1;  // the substep whose sever waits for its stress pass
  for (int64_t step = from; step < to; ++step) {
    if (step == 0) {
      const int target = (total - 1) % 2 == 0 ? 0 : 1;
      timed("kick_drift", [&] {
        const uint32_t n = static_cast<uint32_t>(force_count_);
        dispatch(rec, kernels_->kick_drift, push(n, dt),
                 {{"DispIn", disp_[0]},
                  {"DispOut", disp_[target]},
                  {"Vel", vel_},
                  {"Force", force_},
                  {"Ext", ext_},
                  {"Flags", flags_},
                  {"Classes", classes_},
                  {"List", force_list_}},
                 n);
      });
      cur = target;
      if (contact_recorded()) {
        timed("contact", [&] { record_contact(rec, 0, dt, disp_[cur]); });
        if (cutting_) timed("cut", [&] { record_sever(rec, 0, disp_[cur]); });
      }
    }
    if (beside == step) {
      timed("stress+cut", [&] {
        const uint32_t written = count_stress_beside();
        const bool first = options_.sever_before_stress;  // a test's: the wait runs out
        if (first) record_sever(rec, step, disp_[cur], written);
        if (first) rec.barrier();
        record_stress(rec, disp_[cur], written);
        if (!first) record_sever(rec, step, disp_[cur], written);
      });
    } else {
      timed("stress", [&] { record_stress(rec, disp_[cur]); });
    }
    // The closing kick, or with the next step's kick and drift into the other buffer (its
    // neighbours still read the current one); while tearing, with the tear test after it.
    const bool last = step == total - 1;
    const uint32_t mode = last ? kForceKick : kForceKickDrift;
    const Buffer& out = disp_[last ? cur : 1 - cur];
    // With contact_in_force_, the next substep's contact after the drift in the same pass
    // (without tearing, where no jaws close in it).
    const int64_t contact_step =
        !last && contact_in_force_ && contact_fusable(step + 1) ? step + 1 : -1;
    uint32_t grasp = kContactNoGrasp;
    if (tearing_) {
      // The dirty list's count (tool_contact emptied it unless a sever filled it after).
      if (tear_needs_reset())
        timed("tear: reset", [&] { rec.fill(cut_dirty_, 0, 0, sizeof(uint32_t)); });
      if (contact_step >= 0) fuse_contact(contact_step);
      timed("force+tear", [&] { record_force_tear(rec, mode, dt, disp_[cur], out, contact_step); });
    } else if (contact_step >= 0) {
      grasp = fuse_contact(contact_step);
      timed("force+contact",
            [&] { record_force_contact(rec, dt, disp_[cur], out, contact_step, grasp); });
    } else {
      timed("force", [&] { record_force(rec, mode, dt, disp_[cur], out); });
    }
    if (!last) {
      cur = 1 - cur;
      // The grip's sum of the hold the force pass did, beside the next pass (no barrier).
      if (grasp != kContactNoGrasp) record_grip_row(rec, contact_step, grasp);
      if (contact_recorded() && contact_step < 0)
        timed("contact", [&] { record_contact(rec, step + 1, dt, disp_[cur]); });
      if (contact_recorded() && cutting_ && sever_beside(step + 1, to))
        beside = step + 1;
      else if (contact_recorded() && cutting_)
        timed("cut", [&] { record_sever(rec, step + 1, disp_[cur]); });
    }
  }
  // The samples of the substeps whose contact the force pass did, after the last.
  if (to == total && contact_in_force_) timed("contact: rows", [&] { record_fused_rows(rec); });
}

bool GpuSolver::sever_beside(int64_t step, int64_t to) const {
  // Not where the stress pass writes more than D (principal, tearing) or the band follows it,
  // nor with no stress pass to wait for, nor past what the count of its workgroups holds.
  return options_.sever_beside_stress && step < to && !tearing_ && !principal_ && !band_built() &&
         stress_count_ > 0 && count_ <= options_.sever_beside_max_phyxels &&
         stress_beside_written_ + stress_groups() <= UINT32_MAX;
}

uint64_t GpuSolver::stress_groups() const {
  const uint32_t n = static_cast<uint32_t>(stress_count_);
  const std::array<uint32_t, 3> g =
      group_counts(n * lanes_for(Gather::Stress, n), kernels_->stress.workgroup_size()[0],
                   ctx_->info().max_workgroup_count);
  return uint64_t{g[0]} * g[1] * g[2];
}

uint32_t GpuSolver::count_stress_beside() {
  stress_beside_written_ += stress_groups();
  return static_cast<uint32_t>(stress_beside_written_);
}

void GpuSolver::reset_stress_beside(Recorder& rec) {
  rec.fill(stress_done_, 0);
  stress_beside_written_ = 0;
}

namespace {

using Clock = std::chrono::steady_clock;

// Adds the seconds since `mark` to `into` and moves `mark` to now.
void lap(Clock::time_point& mark, double& into) {
  const Clock::time_point now = Clock::now();
  into += std::chrono::duration<double>(now - mark).count();
  mark = now;
}

}  // namespace

void GpuSolver::advance(int64_t substeps, double dt) {
  advance_paused(substeps, dt, {}, {});
}

void GpuSolver::advance_paused(int64_t substeps, double dt, const std::vector<int64_t>& pauses,
                               const std::function<void(int64_t)>& at) {
  settle();
  const bool asked = near_asked_;  // prefetch_near: for this advance only
  near_asked_ = false;
  const bool checks = checks_asked_;  // prefetch_checks: likewise
  checks_asked_ = false;
  for (size_t p = 0; p < pauses.size(); ++p)
    if (pauses[p] <= 0 || pauses[p] >= substeps || (p > 0 && pauses[p] <= pauses[p - 1]))
      throw std::invalid_argument(
          "GpuSolver::advance_paused: pauses must ascend inside the advance's substeps");
  if (substeps <= 0) return;
  AdvanceHostTimes& t = host_times_;
  ++t.advances;
  Clock::time_point mark = Clock::now();
  // Where the host has nothing to finish after it (no tool samples or cut log to take), the
  // advance returns while its last submission runs.
  const bool finish_here = !tools_.empty() || cutting_ || tearing_;
  if (!tools_.empty()) begin_contact(substeps, dt);  // records its uploads into rec_[0]
  // The advance's log starts empty (begin_contact empties it for cuts).
  if (tearing_ && !cutting_) rec_[0]->fill(cut_log_, 0, 0, sizeof(layout::uvec4));
  // The count a sever beside the stress pass waits for starts anew with the advance.
  if (cutting_) reset_stress_beside(*rec_[0]);
  // Nothing moves (every object asleep, or everything fixed): the state stays as it is.
  if (force_count_ == 0) {
    if (!tools_.empty()) {
      rec_[0]->submit_and_wait();
      finish_contact(substeps, false);
    }
    cut_pass_ += uint32_t(substeps);
    lap(mark, t.rest);
    for (const int64_t k : pauses) at(k);
    return;
  }
  lap(mark, t.rest);
  // read_near's passes at the end of the last submission, where the run loop asked for them.
  const bool near = asked && count_ > 0 && !near_box_.empty();
  if (near) ensure_near_buffers();
  const float fdt = static_cast<float>(dt);
  int cur = 0;
  bool pending[2] = {false, false};
  int which = 0;
  auto wait_for = [&](int k) {
    pending[k] = false;
    rec_[k]->wait();
    ++t.waits;
    lap(mark, t.wait);
  };
  try {
    size_t pause = 0;
    for (int64_t done = 0; done < substeps;) {
      int64_t next = std::min(substeps, done + submit_steps(done));
      if (pause < pauses.size()) next = std::min(next, pauses[pause]);
      Recorder& rec = *rec_[which];
      rec.barrier();  // the previous submission's writes (same queue, submission order)
      record_steps(rec, done, next, substeps, fdt, cur, nullptr);
      if (near && next == substeps) record_near_box(rec, near_box_);
      if (checks && next == substeps) record_checks(rec);
      ctx_->test_note_substeps(substeps_run_ + next);
      lap(mark, t.record);
      rec.submit();
      pending[which] = true;
      ++t.submissions;
      lap(mark, t.submit);
      // Keep at most two command buffers in flight: wait for the older one, then record the
      // next piece while the GPU runs this one.
      const int other = 1 - which;
      if (pending[other]) wait_for(other);
      which = other;
      done = next;
      if (pause < pauses.size() && pauses[pause] == done) {
        // u of this substep: where the last step's fused force pass read it (record_steps).
        shown_ = 1 - cur;
        try {
          at(done);
        } catch (...) {
          shown_ = 0;
          throw;
        }
        shown_ = 0;
        ++pause;
        mark = Clock::now();  // the pause's time is its caller's
      }
    }
    // The last submission is rec_[1 - which]: left running where the host has nothing to
    // finish.
    for (int k = 0; k < 2; ++k) {
      if (!pending[k]) continue;
      if (finish_here || k != 1 - which) {
        wait_for(k);
      } else {
        pending[k] = false;
        in_flight_ = k;
      }
    }
  } catch (...) {
    // Leave no submission behind that a later call would wait on twice.
    for (int k = 0; k < 2; ++k) {
      if (!pending[k]) continue;
      try {
        rec_[k]->wait();
      } catch (...) {
        // The first error is the one to report.
      }
    }
    throw;
  }
  substeps_run_ += substeps;
  cut_pass_ += uint32_t(substeps);  // the passes record_sever numbered from it
  if (cur != 0)
    throw std::logic_error("GpuSolver::advance: displacement ended in the wrong buffer");
  if (!tools_.empty()) finish_contact(substeps, true);
  collect_band_quads();                        // the cuts' quads, where the scene has a band
  if (cutting_ || tearing_) finish_cutting();  // the pairs cut or torn
  near_ready_ = near;
  checks_ready_ = checks;
  lap(mark, t.rest);
}

void GpuSolver::compute_forces() {
  settle();
  Recorder& rec = *rec_[0];
  // The step passes write u only for the force list; the others must match in both buffers.
  rec.copy(disp_[0], disp_[1]);
  rec.barrier();
  record_stress(rec, disp_[0]);  // and the principal stress, while on
  rec.barrier();
  record_force(rec, kForceOnly, 0.0f, disp_[0], disp_[0]);
  rec.submit_and_wait();
}

void GpuSolver::set_state(const std::vector<Vec3>& displacement,
                          const std::vector<Vec3>& velocity) {
  settle();
  if (displacement.size() != count_ || velocity.size() != count_)
    throw std::invalid_argument("GpuSolver::set_state: expected " + std::to_string(count_) +
                                " displacements and velocities");
  upload(*ctx_, disp_[0], to_vec4(displacement));
  upload(*ctx_, vel_, to_vec4(velocity));
  compute_forces();
}

double GpuSolver::bytes_per_phyxel_step() const {
  const double n = count_ > 0 ? double(count_) : 1.0;
  // Per phyxel of a pass (the averages of the whole set); scaled below by the share of the
  // phyxels that each pass visits.
  const double pairs_per_phyxel = double(pairs_) / n;
  // index, and the weight where it is read
  const double stored =
      options_.pair_weights == GpuSolverOptions::PairWeights::Stored ? 1.0 : double(edited_) / n;
  const double per_pair = 4.0 + 4.0 * stored;
  const double regularised = double(regularised_) / n;
  // stress: list 4, offset 4, local 16, u 16, flags 4, A^-1 32, (residual 32 if regularised),
  // D 48
  const double stress =
      4 + 4 + 16 + 16 + 4 + 32 + 32 * regularised + 48 + per_pair * pairs_per_phyxel;
  // force: list 4, offset 4, local 16, u in 16, D 48, ext 16, flags 4, v 16 + 16, f 16, u out 16
  const double force = 4 + 4 + 16 + 16 + 48 + 16 + 4 + 32 + 16 + 16 + per_pair * pairs_per_phyxel;
  // the principal stress (tearing), in the stress pass's gather: out 4 (+ tensor 32)
  const double principal = principal_ ? 4.0 + (tearing_ ? 32.0 : 0.0) : 0.0;
  return ((stress + principal) * double(stress_count_) + force * double(force_count_)) / n;
}

}  // namespace phyxel::gpu

namespace phyxel {

std::unique_ptr<Solver> make_gpu_solver(const PhyxelSet& set, const Vec3& gravity,
                                        const gpu::ContextOptions& options,
                                        const gpu::GpuSolverOptions& solver_options) {
  return std::make_unique<gpu::GpuSolver>(std::make_unique<gpu::Context>(options), set, gravity,
                                          solver_options);
}

}  // namespace phyxel
