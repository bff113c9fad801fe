// GpuSolver: tool-tissue contact with CpuSolver's semantics (engine/solver/cpu_solver.cpp:
// set_tools, set_tool_motion, apply_contacts; engine/solver/contact.h for the response).
//
// At the start of an advance with new motions (begin_contact), all on the GPU and recorded
// into the advance's first command buffer (nothing read back): max |u| and |v| by a reduction
// (solver_max_norm), the broad phase over the force list (tool_broad_phase, tool_broad_scan:
// the phyxels whose current position is inside the chunk's swept bounds grown by
// contact_margin, in ascending order) with the candidate count and the indirect dispatch of
// tool_contact, the motion table copied from a persistent staging buffer, and the contact flags
// cleared. After every drift of every substep (record_steps): tool_contact over the candidates
// (dispatched indirectly, at least one workgroup), whose last workgroup sums the samples (a
// Readback buffer, read once after the advance with the candidate count) and empties the
// dirty list; where a blade resists, tool_resist after it, whose last workgroup sums them instead
// (tool_contact_reduce after it with GpuSolverOptions::resist_reduce off).
// With contact_in_force_ (tearing, no blade or grasper; or no tearing, no blade with a
// threshold, one grasper at most: gpu_solver_force_contact.cpp) the contact of substeps 1 on is
// solver_force_tear's or solver_force_contact's, per candidate into contact_rows_, which
// record_contact_rows sums after the advance's last force pass (tool_contact_reduce over rows:
// every 64 candidates' partial of every row at once, then the samples; the same bits).
// Buffers grow when a chunk needs more and are never reallocated otherwise.
#include <algorithm>
#include <cstddef>
#include <cstring>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"
#include "engine/solver/cutting.h"
#include "engine/solver/suction.h"

namespace phyxel::gpu {

using namespace layout;

namespace {

vec4 to_vec4(const Vec3& x) {
  return {float(x.x()), float(x.y()), float(x.z()), 0.0f};
}

// `b` holds at least `bytes` afterwards: kept when it does, else replaced by one of twice its
// size or `bytes`, whichever is more (contents are not kept).
void reserve(Context& ctx, Buffer& b, uint64_t bytes, MemoryIntent intent, const char* name) {
  if (b && b.size() >= bytes) return;
  b = Buffer(ctx, std::max(bytes, b ? 2 * b.size() : uint64_t{0}), intent, name);
}

}  // namespace

void GpuSolver::set_tools(const std::vector<ContactTool>& tools) {
  settle();
  refresh_band(true);  // no blade left in the cut: all of it
  std::vector<ContactToolShape> shapes;
  for (const ContactTool& t : tools) {
    const bool capsule = t.shape.type == ToolShape::Type::Capsule;
    if (!(t.shape.radius > 0) || !(t.friction >= 0) || (capsule && !(t.shape.length >= 0)))
      throw std::invalid_argument(
          "GpuSolver::set_tools: a tool needs a radius > 0, a length "
          ">= 0 and a friction >= 0");
    const float band = t.blade.cuts() ? float(contact_spacing_) : 0.0f;     // ToolContactSample
    const bool sharp = capsule && t.blade.cuts() && t.blade.threshold > 0;  // on_sharp_point
    shapes.push_back(
        {{float(t.shape.radius), capsule ? float(t.shape.length) : 0.0f, float(t.friction), band},
         {capsule ? kToolCapsule : kToolSphere, sharp ? 1u : 0u, 0u, 0u},
         {float(suction_pull_density(t)), float(t.suction.reach), float(t.suction.flow_speed),
          0.0f}});
  }
  tools_ = tools;
  cutting_ = false;
  for (const ContactTool& t : tools_) cutting_ = cutting_ || t.blade.cuts();
  resisting_ = false;
  sample_in_sever_ = false;
  for (const ContactTool& t : tools_) {
    resisting_ = resisting_ || (t.blade.cuts() && t.blade.threshold > 0 && t.blade.stiffness > 0);
    sample_in_sever_ = sample_in_sever_ || (t.blade.cuts() && t.blade.threshold != 0);
  }
  pending_motion_.clear();
  motion_.clear();
  motion_steps_ = motion_step_ = 0;
  samples_.clear();
  candidates_ = 0;
  blades_near_ = false;
  broad_pending_ = false;
  contact_active_ = false;
  contact_in_force_ = false;
  if (!tools_.empty()) {
    Context& ctx = *ctx_;
    reserve(ctx, tool_shapes_, shapes.size() * sizeof(ContactToolShape), MemoryIntent::Device,
            "contact tools");
    upload(ctx, tool_shapes_, shapes);
    reserve(ctx, contact_flag_, uint64_t{count_} * sizeof(uint32_t), MemoryIntent::Device,
            "contact flags");
    reserve(ctx, candidate_slot_, std::max<uint64_t>(count_, 1) * sizeof(uint32_t),
            MemoryIntent::Device, "contact candidate slot per phyxel");
    if (!contact_count_)
      contact_count_ =
          Buffer(ctx, sizeof(ContactCount) + sizeof(SeverGroups), MemoryIntent::Readback,
                 "contact candidate count", VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
    if (!contact_done_)
      contact_done_ =
          Buffer(ctx, sizeof(uint32_t), MemoryIntent::Device, "contact workgroups done");
  }
  if (cutting_) prepare_cutting();
  if (cutting_) prepare_blade_sides();
  prepare_grasping();
  if (contact_flag_) {  // no flag and no candidate survives a change of tools
    rec_[0]->fill(contact_flag_, 0);
    rec_[0]->fill(candidate_slot_, ~0u);  // no candidate until a broad phase
    // No candidate, and one workgroup of tool_contact, which writes the samples (as
    // tool_broad_scan gives at least).
    rec_[0]->fill(contact_count_, 0, 0, sizeof(uint32_t));
    rec_[0]->fill(contact_count_, 1, offsetof(ContactCount, groups_x), 3 * sizeof(uint32_t));
    rec_[0]->fill(contact_count_, 0, sizeof(ContactCount), sizeof(uint32_t));  // no sever
    rec_[0]->fill(contact_count_, 1, sizeof(ContactCount) + offsetof(SeverGroups, y),
                  3 * sizeof(uint32_t));
    rec_[0]->fill(contact_done_, 0);
    rec_[0]->submit_and_wait();
  }
}

void GpuSolver::set_tool_motion(const std::vector<ToolMotion>& motion) {
  settle();
  if (!tools_.empty() && motion.size() % tools_.size() != 0)
    throw std::invalid_argument("GpuSolver::set_tool_motion: " + std::to_string(motion.size()) +
                                " motions for " + std::to_string(tools_.size()) +
                                " tools (substeps x tools expected)");
  if (!tools_.empty()) refresh_band(false);  // the chunks before the last one: the cut passed
  pending_motion_ = motion;                  // as CpuBackend: empty keeps the last chunk's motions
}

void GpuSolver::record_max_norms(Recorder& rec) {
  const uint32_t threads = kernels_->max_norm.workgroup_size()[0];
  const Buffer* src = &reduce_[1];  // not read at level 0
  uint32_t count = count_;
  for (uint32_t level = 0;; ++level) {
    const uint32_t groups = (count + kScanBlock - 1) / kScanBlock;
    const Buffer& dst = groups == 1 ? max_norm_readback_ : reduce_[level % 2];
    dispatch(rec, kernels_->max_norm, MaxNormPush{count, level},
             {{"Disp", disp_[0]}, {"Vel", vel_}, {"Src", *src}, {"Dst", dst}}, groups * threads);
    if (groups == 1) break;
    rec.barrier();
    src = &dst;
    count = groups;
  }
}

std::pair<double, double> GpuSolver::max_norms() {
  const bool prefetched = checks_ready_;  // prefetch_checks: in the last advance, nothing since
  if (prefetched)
    settle_for_read();
  else
    settle();
  if (count_ == 0) return {0.0, 0.0};
  if (!prefetched) {
    record_max_norms(*rec_[0]);
    rec_[0]->submit_and_wait();
  }
  max_norm_readback_.invalidate();
  vec4 m;
  std::memcpy(&m, max_norm_readback_.mapped(), sizeof m);
  return {double(m.x), double(m.y)};
}

void GpuSolver::record_broad_phase(Recorder& rec) {
  Context& ctx = *ctx_;
  const uint32_t n = static_cast<uint32_t>(force_count_);
  const size_t nt = tools_.size();
  // Room for every entry of the force list (the broad phase may take them all).
  if (std::max<uint32_t>(n, 1) > candidate_capacity_)
    candidate_capacity_ = std::max(std::max<uint32_t>(n, 1), 2 * candidate_capacity_);
  const uint64_t cap = candidate_capacity_;
  reserve(ctx, candidate_list_, cap * sizeof(uint32_t), MemoryIntent::Device, "contact candidates");
  // Per (tool, workgroup of tool_contact): the sum of its candidates' forces, then (tools
  // further on) the axial range of their contacts.
  reserve(ctx, candidate_force_, 2 * uint64_t{partial_capacity()} * nt * sizeof(vec4),
          MemoryIntent::Device, "contact force per workgroup of candidates");
  const uint32_t wg = kernels_->broad_phase.workgroup_size()[0];
  const uint32_t groups = (n + wg - 1) / wg;
  reserve(ctx, broad_groups_, std::max<uint64_t>(groups, 1) * sizeof(uint32_t),
          MemoryIntent::Device, "contact broad phase per workgroup");
  record_max_norms(rec);
  rec.barrier();
  const Bounds b = swept_bounds(tools_, motion_), blades = blade_swept_bounds(tools_, motion_);
  // w 1: the sever takes every candidate (blades_sever_in_reach_only).
  const float every = blades_sever_in_reach_only(tools_) ? 0.0f : 1.0f;
  BroadPhasePush push{
      {float(b.min.x()), float(b.min.y()), float(b.min.z()),
       float(cut_candidate_reach(tools_, contact_spacing_, max_support_))},
      {float(b.max.x()), float(b.max.y()), float(b.max.z()), float(chunk_duration_)},
      n,
      0u,
      groups,
      float(tool_speed(tools_, motion_, chunk_duration_ / double(motion_steps_))),
      {float(blades.min.x()), float(blades.min.y()), float(blades.min.z()), every},
      {float(blades.max.x()), float(blades.max.y()), float(blades.max.z()), 0.0f}};
  auto pass = [&](uint32_t mode) {
    push.mode = mode;
    dispatch(rec, kernels_->broad_phase, push,
             {{"List", force_list_},
              {"Rest", rest_},
              {"Disp", disp_[0]},
              {"Flags", flags_},
              {"MaxNorm", max_norm_readback_},
              {"Group", broad_groups_},
              {"Out", candidate_list_},
              {"Slot", candidate_slot_}},
             groups * wg);
  };
  pass(0);
  rec.barrier();
  dispatch(rec, kernels_->broad_scan, push, {{"Group", broad_groups_}, {"Count", contact_count_}},
           kernels_->broad_scan.workgroup_size()[0]);
  rec.barrier();
  pass(1);
  rec.fill(contact_flag_, 0);  // no stale contact from the last list
  rec.indirect_barrier();
}

void GpuSolver::begin_contact(int64_t substeps, double dt) {
  Context& ctx = *ctx_;
  Recorder& rec = *rec_[0];
  const size_t nt = tools_.size();
  if (!pending_motion_.empty()) {
    motion_ = std::move(pending_motion_);
    pending_motion_.clear();
    motion_steps_ = motion_.size() / nt;
    motion_step_ = 0;
    chunk_duration_ = dt * double(motion_steps_);
    // The motion table in the solver's contact frame (build(): the centre of the rest bounds,
    // rounded to float, the same for every chunk so that where an advance starts changes no
    // bit of the contact and cutting passes).
    const Vec3 origin(contact_origin_.x, contact_origin_.y, contact_origin_.z);
    std::vector<ContactMotion> table(motion_.size());
    for (size_t k = 0; k < motion_.size(); ++k) {
      const ToolMotion& m = motion_[k];
      vec4 to = to_vec4(m.to.position - origin);
      to.w = m.suction_on ? 1.0f : 0.0f;
      table[k] = {to_vec4(m.from.position - origin), to_vec4(m.from.axis), to, to_vec4(m.to.axis)};
    }
    const uint64_t table_bytes = table.size() * sizeof(ContactMotion);
    reserve(ctx, motion_upload_, table_bytes, MemoryIntent::Upload, "contact motion staging");
    reserve(ctx, motion_table_, table_bytes, MemoryIntent::Device, "contact motion");
    std::memcpy(motion_upload_.mapped(), table.data(), table_bytes);
    rec.copy(motion_upload_, motion_table_, table_bytes);
    if (cutting_) upload_cut_quads(rec);
    broad_pending_ = true;
  }
  if (broad_pending_ && motion_steps_ > 0) {
    record_broad_phase(rec);  // after the copy: the barriers in it order the table too
    broad_pending_ = false;
  }
  reserve(ctx, samples_buffer_, 2 * uint64_t(substeps) * nt * sizeof(vec4), MemoryIntent::Readback,
          "contact samples");
  contact_active_ = motion_steps_ > 0 && force_count_ > 0;
  // The contact after substep 0 inside solver_force_tear, its rows summed after the advance
  // (tool_contact's own sums of each substep otherwise), where nothing else acts between the
  // contact and the next stress pass and the rows fit in 64 MiB.
  const uint64_t row_bytes = 2 * nt * uint64_t{partial_capacity()} * PHYXEL_WORKGROUP_SIZE * 16;
  // Without tearing: no blade reads the sample in the substep, one grasper at most (its hold
  // inside the pass), no band (the force pass's ext is the band's).
  const size_t graspers = std::count_if(tools_.begin(), tools_.end(),
                                        [](const ContactTool& t) { return t.grasp.grasps(); });
  const bool tears = tearing_ && !cutting_ && !grasping_;
  const bool holds = !tearing_ && !sample_in_sever_ && !band_ &&
                     (graspers == 0 || (graspers == 1 && options_.grasp_in_contact));
  contact_in_force_ = options_.contact_in_force && contact_fused() && (tears || holds) &&
                      uint64_t(substeps) * row_bytes <= (uint64_t{64} << 20);
  contact_runs_.clear();
  rows_grasp_ = kContactNoGrasp;
  if (contact_in_force_ && graspers == 1) {
    rows_grasp_ =
        static_cast<uint32_t>(std::find_if(tools_.begin(), tools_.end(),
                                           [](const ContactTool& t) { return t.grasp.grasps(); }) -
                              tools_.begin());
    reserve(ctx, grip_rows_, 2 * uint64_t(substeps) * nt * sizeof(vec4), MemoryIntent::Device,
            "grip rows of the force pass's holds");
    rec.fill(grip_rows_, 0);  // substeps without a hold subtract nothing
  }
  if (contact_in_force_) {
    reserve(ctx, contact_rows_, uint64_t(substeps) * row_bytes, MemoryIntent::Device,
            "contact rows of the force pass");
    reserve(ctx, row_partials_, uint64_t(substeps) * row_bytes / PHYXEL_WORKGROUP_SIZE,
            MemoryIntent::Device, "contact rows' partials per 64 candidates");
  }
  if (cutting_) rec.fill(cut_log_, 0, 0, sizeof(uvec4));  // the advance's log starts empty
}

uint32_t GpuSolver::contact_motion_row(int64_t step) const {
  // This substep's row of the motion table; past the chunk the tools keep the last end pose.
  return static_cast<uint32_t>(
      std::min<uint64_t>(motion_step_ + uint64_t(step), motion_steps_ - 1));
}

uint32_t GpuSolver::sample_fuse(bool sums) const {
  if (!sums) return 0u;
  return cut_dirty_ ? kContactFuseReduce | kContactFuseDirtyReset : kContactFuseReduce;
}

uint32_t GpuSolver::contact_hold(int64_t step) const {
  return motion_step_ + uint64_t(step) >= motion_steps_ ? 1u : 0u;
}

void GpuSolver::record_contact_rows(Recorder& rec, int64_t first, int64_t end) {
  if (end <= first) return;
  const uint32_t nt = static_cast<uint32_t>(tools_.size());
  const uint32_t rows = static_cast<uint32_t>(end - first);
  const uint32_t cap = partial_capacity();
  const uint32_t wg = kernels_->contact_reduce.workgroup_size()[0];
  ContactReducePush push{rows, nt, cap, static_cast<uint32_t>(first), 0u, kContactNoGrasp, 0u};
  const bool grip = rows_grasp_ != kContactNoGrasp;
  part_begin(rec, "contact: rows");
  // Every (row, tool, 64 candidates) partial at once, then the samples from them.
  dispatch(rec, kernels_->contact_reduce, push,
           {{"Force", contact_rows_},
            {"Samples", samples_buffer_},
            {"Count", contact_count_},
            {"List", candidate_list_},
            {"Flags", flags_},
            {"Partials", row_partials_},
            {"Held", contact_count_},  // unread without a grasp
            {"GripForce", candidate_force_}},
           rows * nt * cap * wg);
  rec.barrier();
  push.sums = 1u;
  push.grasp = rows_grasp_;  // its grip rows subtracted after the sums
  dispatch(rec, kernels_->contact_reduce, push,
           {{"Force", row_partials_},
            {"Samples", samples_buffer_},
            {"Count", contact_count_},
            {"List", candidate_list_},
            {"Flags", flags_},
            {"Partials", contact_rows_},  // unwritten with sums 1
            {"Held", contact_count_},
            {"GripForce", grip ? grip_rows_ : candidate_force_}},
           rows * nt * wg);
  part_end(rec);
}

void GpuSolver::record_contact(Recorder& rec, int64_t step, float dt, const Buffer& disp) {
  const uint32_t nt = static_cast<uint32_t>(tools_.size());
  const bool fused = contact_fused();
  const uint32_t grasp = grasp_in_contact(step);
  // Its own grasp passes read the sample: tool_contact writes it then (before grasp_passes_left's
  // update of grip_closed_, which only record_grasp reads after).
  const bool grasp_passes = grasping_ && grasp_passes_left(step, grasp);
  // The samples apart: tool_contact only empties the dirty list; record_sever sums them.
  const bool apart = options_.sums_apart && fused && cutting_ && !sample_in_sever_ && !grasp_passes;
  const uint32_t fuse = apart ? (cut_dirty_ ? kContactFuseDirtyReset : 0u) : sample_fuse(fused);
  sums_pending_ = apart ? step : -1;
  sums_grasp_ = grasp;
  const ContactPush push{contact_origin_,
                         static_cast<uint32_t>(step),
                         dt,
                         nt,
                         contact_motion_row(step),
                         contact_hold(step),  // past the chunk: the last pose
                         partial_capacity(),
                         fuse,
                         grasp,
                         count_,
                         cutting_ ? cut_pass(step) : 0u,
                         cutting_ ? count_ : 0u};
  // Stand-ins of the grip's buffers where no grasper's hold is in this pass.
  const bool grip = grasp != kContactNoGrasp;
  part_begin(rec, "contact: tool");
  dispatch_indirect(rec, kernels_->contact, push,
                    {{"List", candidate_list_},
                     {"Rest", rest_},
                     {"Disp", disp},
                     {"Vel", vel_},
                     {"Ext", ext_},
                     {"Flags", flags_},
                     {"Tools", tool_shapes_},
                     {"Motion", motion_table_},
                     {"Force", candidate_force_},
                     {"Contact", contact_flag_},
                     {"Count", contact_count_},
                     {"Samples", samples_buffer_},
                     {"Dirty", cut_dirty_ ? cut_dirty_ : contact_done_},  // unwritten without
                     {"Done", contact_done_},
                     {"Grip", grip ? grip_ : contact_count_},  // unread without (32 bytes)
                     {"Held", grip ? grip_count_ : contact_count_},
                     {"GripForce", grip ? grip_force_ : candidate_force_},
                     {"GripOf", grip ? grip_of_ : contact_done_},
                     {"Slot", candidate_slot_},
                     {"Sides", cutting_ ? cut_sides_ : contact_done_},  // unread without
                     {"Quads", cutting_ ? cut_quads_ : contact_done_}},
                    contact_count_, offsetof(ContactCount, groups_x));
  part_end(rec);
  if (!fused) {  // tool_resist adds to the partials and sums them, or tool_contact_reduce after it
    rec.barrier();
    part_begin(rec, "contact: resist");
    record_resist(rec, step, dt, disp);
    part_end(rec);
  }
  if (!fused && !resist_fused()) {
    rec.barrier();
    part_begin(rec, "contact: reduce");
    dispatch(rec, kernels_->contact_reduce,
             ContactReducePush{0u, nt, partial_capacity(), static_cast<uint32_t>(step), 0u,
                               kContactNoGrasp, 0u},
             {{"Force", candidate_force_},
              {"Samples", samples_buffer_},
              {"Count", contact_count_},
              {"List", candidate_list_},
              {"Flags", flags_},
              {"Partials", candidate_force_},  // unwritten with rows 0
              {"Held", contact_count_},        // unread without a grasp
              {"GripForce", candidate_force_}},
             nt * kernels_->contact_reduce.workgroup_size()[0]);
    part_end(rec);
  }
  if (grasp_passes) {
    rec.barrier();
    part_begin(rec, "contact: grasp");
    record_grasp(rec, step, dt, disp, grasp);
    part_end(rec);
  }
}

void GpuSolver::finish_contact(int64_t substeps, bool ran) {
  samples_.clear();
  if (motion_steps_ == 0) return;  // no motion yet: as the CPU, no samples
  const size_t nt = tools_.size();
  samples_.assign(size_t(substeps) * nt, ToolContactSample{});
  contact_count_.invalidate();
  ContactCount count;
  SeverGroups sever;
  std::memcpy(&count, contact_count_.mapped(), sizeof count);
  std::memcpy(&sever, static_cast<const char*>(contact_count_.mapped()) + sizeof count,
              sizeof sever);
  candidates_ = count.total;
  blades_near_ = cutting_ && sever.x != 0;
  if (contact_active_ && ran) {
    samples_buffer_.invalidate();
    // Two rows per sample (tool_contact_reduce): force and count, the contacts' axial range.
    std::vector<vec4> felt(2 * samples_.size());
    std::memcpy(felt.data(), samples_buffer_.mapped(), felt.size() * sizeof(vec4));
    for (size_t k = 0; k < samples_.size(); ++k) {
      const vec4& f = felt[2 * k];
      const vec4& range = felt[2 * k + 1];
      samples_[k].force = Vec3(f.x, f.y, f.z);
      samples_[k].contacts = static_cast<uint32_t>(f.w);
      samples_[k].held = static_cast<uint32_t>(range.z);  // tool_grasp's reduction
      if (range.x <= range.y) {
        samples_[k].axial_min = range.x;
        samples_[k].axial_max = range.y;
      }
    }
  }
  motion_step_ += size_t(substeps);
}

}  // namespace phyxel::gpu
