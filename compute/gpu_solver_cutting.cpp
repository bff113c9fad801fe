// GpuSolver: cutting with CpuSolver's semantics (engine/solver/cpu_solver_cutting.cpp,
// engine/solver/cutting.h). Per substep, after the contact reduction and in the same command
// buffer: the dirty list's header reset (unless tool_contact emptied it) and tool_sever over the
// candidates (indirect), whose last workgroup reruns the precompute of the phyxels it put in the
// dirty list (no dependent dispatch where nothing was severed). Severed pairs keep their CSR slots
// with weight 0, which the step passes read for phyxels flagged kFlagPairsEdited. After the
// advance, the log of severed pairs is read back once, sorted and appended to the host's log.
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"
#include "engine/solver/cutting.h"

namespace phyxel::gpu {

using namespace layout;

namespace {

vec4 to_vec4(const Vec3& x, float w = 0.0f) {
  return {float(x.x()), float(x.y()), float(x.z()), w};
}

bool by_pair(const SeveredPair& a, const SeveredPair& b) {
  return a.i != b.i ? a.i < b.i : a.j < b.j;
}

// A PassTimer pointer off for a scope and back on at its end, also when the scope throws.
class TimerOff {
 public:
  TimerOff(PassTimer*& timer, bool off) : timer_(timer), kept_(timer) {
    if (off) timer = nullptr;
  }
  ~TimerOff() { timer_ = kept_; }
  TimerOff(const TimerOff&) = delete;
  TimerOff& operator=(const TimerOff&) = delete;

 private:
  PassTimer*& timer_;
  PassTimer* const kept_;
};

}  // namespace

void GpuSolver::prepare_cutting() {
  Context& ctx = *ctx_;
  if (!cut_dirty_)
    cut_dirty_ = Buffer(ctx, (uint64_t{count_} + 1) * sizeof(uint32_t), MemoryIntent::Device,
                        "cut dirty phyxels");
  if (!cut_done_) {
    cut_done_ = Buffer(ctx, sizeof(uint32_t), MemoryIntent::Device, "cut workgroups done");
    rec_[0]->fill(cut_done_, 0);
    rec_[0]->barrier();
  }
  if (!cut_log_) {
    log_capacity_ = 4096;
    cut_log_ = Buffer(ctx, (uint64_t{log_capacity_} + 1) * sizeof(uvec4), MemoryIntent::Readback,
                      "cut log");
  }
  if (alive_.empty()) alive_.assign(pairs_, 1);
}

// The side entries [tool][phyxel], then the normals they were learned on, then two words per
// tool for the blade's cutting state (blade_edge.glsl).
void GpuSolver::prepare_blade_sides() {
  const uint64_t entries = std::max<uint64_t>(1, 2 * (uint64_t{count_} + 1) * tools_.size());
  cut_sides_ =
      Buffer(*ctx_, entries * sizeof(uint32_t), MemoryIntent::Device, "blade side entries");
  upload(*ctx_, cut_sides_, std::vector<uint32_t>(entries, 0u));
}

// The side entries' pass of a substep of the advance (CpuSolver::apply_cuts counts one per
// substep; the entries of the last substep have cut_pass_ after it).
uint32_t GpuSolver::cut_pass(int64_t step) const {
  return cut_pass_ + uint32_t(step) + 1u;
}

std::vector<std::vector<BladeSide>> GpuSolver::blade_sides() {
  settle();
  std::vector<std::vector<BladeSide>> kept(tools_.size());
  if (!cutting_) return kept;
  const size_t nt = tools_.size();
  const std::vector<uint32_t> entries =
      download<uint32_t>(*ctx_, cut_sides_, 2 * uint64_t{count_} * nt);
  for (size_t t = 0; t < nt; ++t)
    for (uint32_t i = 0; i < count_ && tools_[t].blade.cuts(); ++i)
      if (const uint32_t side = side_at_start(entries[t * count_ + i], cut_pass_ + 1);
          side != kSideNone)
        kept[t].push_back({i, side, entries[(nt + t) * count_ + i]});
  return kept;
}

void GpuSolver::restore_blade_sides(const std::vector<std::vector<BladeSide>>& kept) {
  settle();
  if (kept.size() > tools_.size())
    throw std::invalid_argument("GpuSolver::restore_blade_sides: sides for " +
                                std::to_string(kept.size()) + " tools, the scene has " +
                                std::to_string(tools_.size()));
  if (!cutting_) return;
  const size_t nt = tools_.size();
  std::vector<uint32_t> entries(2 * uint64_t{count_} * nt, 0u);
  for (size_t t = 0; t < kept.size(); ++t)
    for (const BladeSide& b : kept[t]) {
      if (!tools_[t].blade.cuts() || b.phyxel >= count_ ||
          (b.side != kSidePlus && b.side != kSideMinus))
        throw std::invalid_argument("GpuSolver::restore_blade_sides: bad side for phyxel " +
                                    std::to_string(b.phyxel) + " of tool " + std::to_string(t));
      entries[t * count_ + b.phyxel] = side_entry(cut_pass_, kSideNone, b.side);
      entries[(nt + t) * count_ + b.phyxel] = b.normal;
    }
  upload(*ctx_, cut_sides_, entries);
}

// Where the next pass (cut_pass_ + 1) reads a blade's cutting state (blade_state_index): the
// word after the side entries and normals; it holds cut_pass_ + 1 where the state is on.
uint64_t GpuSolver::blade_state_word(size_t tool) const {
  return 2 * (uint64_t{count_} * tools_.size() + tool) + (cut_pass_ & 1u);
}

std::vector<uint8_t> GpuSolver::blades_cutting() {
  settle();
  std::vector<uint8_t> on(tools_.size(), 0);
  for (size_t t = 0; t < on.size() && cutting_; ++t)
    on[t] = download<uint32_t>(*ctx_, cut_sides_, 1, blade_state_word(t) * 4)[0] == cut_pass_ + 1u;
  return on;
}

void GpuSolver::restore_blades_cutting(const std::vector<uint8_t>& on) {
  settle();
  for (size_t t = 0; t < on.size(); ++t) {
    if (on[t] == 0) continue;
    if (t >= tools_.size() || !cutting_ || !(tools_[t].blade.threshold > 0))
      throw std::invalid_argument("GpuSolver::restore_blades_cutting: tool " + std::to_string(t) +
                                  " has no blade with a threshold");
    upload(*ctx_, cut_sides_, std::vector<uint32_t>{cut_pass_ + 1u}, blade_state_word(t) * 4);
  }
}

void GpuSolver::upload_cut_quads(Recorder& rec) {
  // Rows: the chunk's substeps, then the last end pose held (CpuSolver: from = to).
  const size_t nt = tools_.size();
  const Vec3 origin(contact_origin_.x, contact_origin_.y, contact_origin_.z);
  std::vector<CutQuad> table((motion_steps_ + 1) * nt);
  for (size_t row = 0; row <= motion_steps_; ++row) {
    for (size_t t = 0; t < nt; ++t) {
      const Blade& blade = tools_[t].blade;
      CutQuad& q = table[row * nt + t];
      if (!blade.cuts()) {
        q.edge = {0, 0, 0, -1};
        continue;
      }
      ToolMotion m = motion_[std::min(row, motion_steps_ - 1) * nt + t];
      if (row == motion_steps_) m.from = m.to;
      const double reach = blade_reach(blade, contact_spacing_);
      const phyxel::CutQuad quad = swept_quad(blade, m.from, m.to, reach);
      // The w components carry the blade body's strip (CpuSolver's body_strip): its radius,
      // and how far back along the edge the blade's end and tip are from p2 and p3.
      const ToolShape& body = tools_[t].shape;
      const double radius = body.type == ToolShape::Type::Capsule ? body.radius : 0.0;
      const EdgeFrame held = edge_frame(blade, quad, m.to, radius, reach);
      q.axis = to_vec4(m.to.axis, 0.0f);  // w unread
      q.frame_tip = to_vec4(held.tip - origin, float(held.length));
      q.frame_axis = to_vec4(held.axis, float(held.front));
      q.frame_edge = to_vec4(held.edge, blade_advances(quad, m.from, m.to) ? 1.0f : 0.0f);
      q.resist = {float(held.stiffness), float(held.depth), float(held.tip_motion),
                  float(held.end_motion)};
      const Vec3 end = m.to.position + blade.length * m.to.axis;
      q.p0 = to_vec4(quad.corner[0] - origin, float(radius));
      q.p1 = to_vec4(quad.corner[1] - origin, float(side_band(radius, contact_spacing_)));
      q.p2 = to_vec4(quad.corner[2] - origin, float((end - quad.corner[2]).dot(quad.edge)));
      q.p3 =
          to_vec4(quad.corner[3] - origin, float((m.to.position - quad.corner[3]).dot(quad.edge)));
      q.edge = to_vec4(quad.edge, float(blade.threshold));
    }
  }
  Context& ctx = *ctx_;
  const uint64_t bytes = table.size() * sizeof(CutQuad);
  if (!cut_quad_upload_ || cut_quad_upload_.size() < bytes) {
    cut_quad_upload_ = Buffer(ctx, bytes * 2, MemoryIntent::Upload, "cut quads staging");
    cut_quads_ = Buffer(ctx, bytes * 2, MemoryIntent::Device, "cut quads");
  }
  std::memcpy(cut_quad_upload_.mapped(), table.data(), bytes);
  rec.copy(cut_quad_upload_, cut_quads_, bytes);
}

uint32_t GpuSolver::cut_table_row(int64_t step) const {
  return static_cast<uint32_t>(std::min<uint64_t>(motion_step_ + uint64_t(step), motion_steps_));
}

void GpuSolver::record_sever(Recorder& rec, int64_t step, const Buffer& disp,
                             uint32_t stress_written) {
  const bool beside = stress_written != 0;
  const uint32_t row = cut_table_row(step);
  // Beside the stress pass, record_steps times the two as one.
  const TimerOff parts(part_timer_, beside);
  // record_steps put a barrier after the contact: the samples of this substep are written.
  if (!contact_fused() && !resist_fused()) {  // else tool_contact or tool_resist emptied it
    part_begin(rec, "cut: reset");
    record_dirty_reset(rec);
    part_end(rec);
  }
  part_begin(rec, "cut: sever");
  // tool_contact left the samples: summed beside the sever (which does not read them), no barrier.
  const bool apart = sums_pending_ == step;
  if (apart) record_sums_apart(rec);
  const SeverPush push{contact_origin_,
                       uint32_t(tools_.size()),
                       row,
                       uint32_t(step),
                       log_capacity_,
                       cut_pass(step),
                       count_,
                       stress_written,  // record_stress's epoch
                       lanes_for(Gather::Stress, uint32_t(stress_count_)),
                       uint32_t(stress_count_),
                       GpuSolver::push(0, 0.0f).weights,
                       0u,
                       0u};
  // A blade with a threshold keeps sides (sample_in_sever_): else the pass without them.
  const Pipeline& sever =
      beside ? (sample_in_sever_ ? kernels_->sever_sided_beside : kernels_->sever_beside)
             : (sample_in_sever_ ? kernels_->sever_sided : kernels_->sever);
  dispatch_indirect(rec, sever, push,
                    {{"List", candidate_list_},
                     {"Rest", rest_},
                     {"Disp", disp},
                     {"Offset", nbr_offset_},
                     {"IndexLo", nbr_index_.lo()},
                     {"WeightLo", weight_.lo()},
                     {"Flags", flags_},
                     {"Quads", cut_quads_},
                     {"Samples", apart ? cut_quads_ : samples_buffer_},  // unread apart
                     {"Dirty", cut_dirty_},
                     {"Log", cut_log_},
                     {"Count", contact_count_},
                     {"IndexHi", nbr_index_.hi()},
                     {"WeightHi", weight_.hi()},
                     {"Local", local_},
                     {"Classes", classes_},
                     {"Ainv", ainv_},
                     {"Resid", resid_},
                     {"Done", cut_done_},
                     {"Sides", cut_sides_},
                     {"Stress", stress_},
                     {"StressList", stress_list_},
                     {"StressDone", stress_done_}},
                    contact_count_, sizeof(ContactCount));
  part_end(rec);
}

void GpuSolver::record_sums_apart(Recorder& rec) {
  const uint32_t nt = static_cast<uint32_t>(tools_.size());
  const bool grip = sums_grasp_ != kContactNoGrasp;
  // Only buffers the sever neither writes nor reads beside it (Flags: a stand-in, unread).
  dispatch(rec, kernels_->contact_reduce,
           ContactReducePush{0u, nt, partial_capacity(), static_cast<uint32_t>(sums_pending_), 0u,
                             sums_grasp_, count_},
           {{"Force", candidate_force_},
            {"Samples", samples_buffer_},
            {"Count", contact_count_},
            {"List", candidate_list_},
            {"Flags", candidate_list_},
            {"Partials", candidate_force_},  // unwritten with rows 0
            {"Held", grip ? grip_count_ : contact_count_},
            {"GripForce", grip ? grip_force_ : candidate_force_}},
           nt * kernels_->contact_reduce.workgroup_size()[0]);
  sums_pending_ = -1;
}

void GpuSolver::record_resist(Recorder& rec, int64_t step, float dt, const Buffer& disp) {
  const uint32_t row = cut_table_row(step);
  // Summing the samples itself (resist_fused), and emptying the dirty list as tool_contact would.
  const uint32_t fuse = sample_fuse(resist_fused());
  const ResistPush push{contact_origin_, dt,   uint32_t(tools_.size()), row,   partial_capacity(),
                        uint32_t(step),  fuse, cut_pass(step),          count_};
  dispatch_indirect(rec, kernels_->resist, push,
                    {{"List", candidate_list_},
                     {"Rest", rest_},
                     {"Disp", disp},
                     {"Vel", vel_},
                     {"Ext", ext_},
                     {"Flags", flags_},
                     {"Offset", nbr_offset_},
                     {"IndexLo", nbr_index_.lo()},
                     {"WeightLo", weight_.lo()},
                     {"Quads", cut_quads_},
                     {"Force", candidate_force_},
                     {"Count", contact_count_},
                     {"IndexHi", nbr_index_.hi()},
                     {"WeightHi", weight_.hi()},
                     {"Samples", samples_buffer_},
                     {"Done", contact_done_},
                     {"Dirty", cut_dirty_ ? cut_dirty_ : contact_done_},  // unwritten without
                     {"Sides", cut_sides_}},
                    contact_count_, offsetof(ContactCount, groups_x));
}

void GpuSolver::record_dirty_reset(Recorder& rec) {
  rec.fill(cut_dirty_, 0, 0, sizeof(uint32_t));  // the count
  rec.barrier();
}

void GpuSolver::record_precompute(Recorder& rec, const PrecomputePush& pc, const Buffer& list,
                                  uint32_t elements) {
  dispatch(rec, kernels_->precompute, pc,
           {{"Offset", nbr_offset_},
            {"IndexLo", nbr_index_.lo()},
            {"WeightLo", weight_.lo()},
            {"Local", local_},
            {"Flags", flags_},
            {"Classes", classes_},
            {"Rest", rest_},
            {"Ainv", ainv_},
            {"Resid", resid_},
            {"List", list},
            {"IndexHi", nbr_index_.hi()},
            {"WeightHi", weight_.hi()}},
           elements);
}

void GpuSolver::finish_cutting() {
  cut_log_.invalidate();
  uvec4 header;
  std::memcpy(&header, cut_log_.mapped(), sizeof header);
  if (header.x > 0) take_cut_log(header.x);
  if ((header.y & kCutLogStressMissed) != 0)
    throw VulkanError(ctx_->info().name +
                      ": the cut's sever beside the stress pass found that pass not run (this "
                      "driver does not run a dispatch beside the one recorded before it); the "
                      "stress after the cut is not to be trusted. Run with "
                      "PHYXEL_SEVER_BESIDE_STRESS=0 (the sever in a pass of its own)");
}

void GpuSolver::take_cut_log(uint32_t found) {
  std::vector<SeveredPair> fresh;
  if (found <= log_capacity_) {
    std::vector<uvec4> entries(found);
    std::memcpy(entries.data(), static_cast<const uvec4*>(cut_log_.mapped()) + 1,
                found * sizeof(uvec4));
    fresh.reserve(found);
    for (const uvec4& e : entries) {
      float t;
      std::memcpy(&t, &e.z, sizeof t);
      fresh.push_back({e.x, e.y, t, e.w != 0});
    }
  } else {
    // More than the log holds: compare the weights with the last known pairs (t unknown: the
    // middle), then grow the log for the next advance.
    const std::vector<float> w = weight_.download<float>(*ctx_);
    const NeighbourLists& nbr = neighbours_;
    for (uint32_t i = 0; i < count_; ++i)
      for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k)
        if (nbr.index[k] > i && alive_[k] && w[k] == 0.0f)
          fresh.push_back({i, nbr.index[k], 0.5f, !cutting_});
    while (log_capacity_ < found) log_capacity_ *= 2;
    cut_log_ = Buffer(*ctx_, (uint64_t{log_capacity_} + 1) * sizeof(uvec4), MemoryIntent::Readback,
                      "cut log");
  }
  std::sort(fresh.begin(), fresh.end(), by_pair);
  for (const SeveredPair& p : fresh) mark_severed(p);
  severed_.insert(severed_.end(), fresh.begin(), fresh.end());
}

void GpuSolver::mark_severed(const SeveredPair& p) {
  for (const size_t k : {neighbours_.slot(p.i, p.j), neighbours_.slot(p.j, p.i)})
    if (k != NeighbourLists::kNoSlot) alive_[k] = 0;
}

std::vector<SeveredPair> GpuSolver::severed_since(size_t first) {
  wait_in_flight();  // the host's log only: a prefetched read_near stays
  return {severed_.begin() + std::min(first, severed_.size()), severed_.end()};
}

std::vector<uint8_t> GpuSolver::pair_alive() {
  settle();
  if (!alive_.empty()) return alive_;
  // Without cuts: every pair with a weight (removed phyxels' pairs have none).
  const std::vector<float> w = weight_.download<float>(*ctx_);
  std::vector<uint8_t> alive(w.size());
  for (size_t k = 0; k < w.size(); ++k) alive[k] = w[k] != 0.0f;
  return alive;
}

void GpuSolver::sever_pairs(const std::vector<SeveredPair>& pairs) {
  settle();
  if (pairs.empty()) return;
  if (alive_.empty()) alive_.assign(pairs_, 1);
  std::vector<uint32_t> flags;
  std::vector<float> weights;
  read_flags_and_weights(flags, weights);
  const NeighbourLists& nbr = neighbours_;
  std::vector<uint32_t> touched;
  std::vector<SeveredPair> fresh;
  for (const SeveredPair& p : pairs) {
    if (p.i >= count_ || p.j >= count_)
      throw std::invalid_argument("sever_pairs: no phyxel " + std::to_string(std::max(p.i, p.j)));
    const size_t ij = nbr.slot(p.i, p.j), ji = nbr.slot(p.j, p.i);
    if (ij == NeighbourLists::kNoSlot || ji == NeighbourLists::kNoSlot)
      throw std::invalid_argument("sever_pairs: phyxels " + std::to_string(p.i) + " and " +
                                  std::to_string(p.j) + " are not neighbours");
    if (weights[ij] == 0.0f && weights[ji] == 0.0f) continue;  // severed before
    weights[ij] = weights[ji] = 0.0f;
    flags[p.i] |= kFlagPairsEdited;
    flags[p.j] |= kFlagPairsEdited;
    touched.push_back(p.i);
    touched.push_back(p.j);
    fresh.push_back(p.i < p.j ? p : SeveredPair{p.j, p.i, 1.0f - p.t});
  }
  std::sort(fresh.begin(), fresh.end(), by_pair);
  for (const SeveredPair& p : fresh) mark_severed(p);
  severed_.insert(severed_.end(), fresh.begin(), fresh.end());
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  if (touched.empty()) return;
  apply_edit(flags, weights, touched);
  compute_forces();
}

}  // namespace phyxel::gpu
