// GpuSolver: tool-tissue contact with CpuSolver's semantics (engine/solver/cpu_solver.cpp:
// set_tools, set_tool_motion, apply_contacts; engine/surgery/contact.h for the response).
//
// At the start of an advance with new motions (begin_contact): max |u| and max |v| from a GPU
// reduction (solver_max_norm, 16 bytes back), the broad phase on the host exactly as the CPU's
// (ContactBroadPhase over the set at construction, bounds = swept_bounds of the chunk's
// motions, reach = contact_reach(largest spacing, max |u|, max |v|, chunk duration)), the
// candidates of awake objects and the motion table copied from persistent staging buffers in
// the advance's first command buffer, and the contact flags cleared. After every drift of
// every substep (record_steps): tool_contact over the candidates, then tool_contact_reduce
// into the samples (a Readback buffer, read once after the advance). Buffers grow when a chunk
// needs more and are never reallocated otherwise.
#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "compute/gpu_solver.h"
#include "compute/gpu_solver_kernels.h"

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
  std::vector<ContactToolShape> shapes;
  for (const ContactTool& t : tools) {
    const bool capsule = t.shape.type == ToolShape::Type::Capsule;
    if (!(t.shape.radius > 0) || !(t.friction >= 0) || (capsule && !(t.shape.length >= 0)))
      throw std::invalid_argument(
          "GpuSolver::set_tools: a tool needs a radius > 0, a length "
          ">= 0 and a friction >= 0");
    shapes.push_back(
        {{float(t.shape.radius), capsule ? float(t.shape.length) : 0.0f, float(t.friction), 0.0f},
         {capsule ? kToolCapsule : kToolSphere, 0u, 0u, 0u}});
  }
  tools_ = tools;
  pending_motion_.clear();
  motion_.clear();
  motion_steps_ = motion_step_ = 0;
  broad_list_.clear();
  candidates_.clear();
  samples_.clear();
  contact_active_ = false;
  if (!tools_.empty()) {
    Context& ctx = *ctx_;
    reserve(ctx, tool_shapes_, shapes.size() * sizeof(ContactToolShape), MemoryIntent::Device,
            "contact tools");
    upload(ctx, tool_shapes_, shapes);
    reserve(ctx, contact_flag_, uint64_t{count_} * sizeof(uint32_t), MemoryIntent::Device,
            "contact flags");
    reserve(ctx, max_norm_readback_, sizeof(vec4), MemoryIntent::Readback, "max |u|, |v|");
  }
  if (contact_flag_) {  // no flag survives a change of tools
    rec_[0]->fill(contact_flag_, 0);
    rec_[0]->submit_and_wait();
  }
}

void GpuSolver::set_tool_motion(const std::vector<ToolMotion>& motion) {
  if (!tools_.empty() && motion.size() % tools_.size() != 0)
    throw std::invalid_argument("GpuSolver::set_tool_motion: " + std::to_string(motion.size()) +
                                " motions for " + std::to_string(tools_.size()) +
                                " tools (substeps x tools expected)");
  pending_motion_ = motion;  // as CpuBackend: empty keeps the last chunk's motions
}

std::pair<double, double> GpuSolver::max_norms() {
  if (count_ == 0) return {0.0, 0.0};
  Recorder& rec = *rec_[0];
  const uint32_t threads = kernels_->max_norm.workgroup_size()[0];
  const Buffer* src = &reduce_[1];  // not read at level 0
  uint32_t count = count_;
  for (uint32_t level = 0;; ++level) {
    const uint32_t groups = (count + kScanBlock - 1) / kScanBlock;
    const Buffer& dst = groups == 1 ? max_norm_readback_ : reduce_[level % 2];
    dispatch(rec, kernels_->max_norm, MaxNormPush{count, level}, {disp_[0], vel_, *src, dst},
             groups * threads);
    if (groups == 1) break;
    rec.barrier();
    src = &dst;
    count = groups;
  }
  rec.submit_and_wait();
  max_norm_readback_.invalidate();
  vec4 m;
  std::memcpy(&m, max_norm_readback_.mapped(), sizeof m);
  return {double(m.x), double(m.y)};
}

void GpuSolver::filter_candidates(Recorder& rec) {
  candidates_.clear();
  for (const uint32_t i : broad_list_)
    if (awake_[object_[i]] && !(phyxel_flags_[i] & (kFixed | kRemoved))) candidates_.push_back(i);
  if (!candidates_.empty()) {
    const uint64_t bytes = candidates_.size() * sizeof(uint32_t);
    std::memcpy(candidate_upload_.mapped(), candidates_.data(), bytes);
    rec.copy(candidate_upload_, candidate_list_, bytes);
  }
  rec.fill(contact_flag_, 0);  // no stale contact from the last list
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
    // The CPU's broad phase for the chunk (CpuSolver::set_tool_motion).
    const auto [max_u, max_v] = max_norms();
    const double reach = contact_reach(reach_spacing_, max_u, max_v, dt * double(motion_steps_));
    broad_list_ = broad_->candidates(swept_bounds(tools_, motion_), reach);
    // The motion table in a frame at the first tool's first pose, rounded to float so that the
    // shader subtracts exactly this origin from the rest positions.
    const Vec3 origin = motion_[0].from.position.cast<float>().cast<double>();
    contact_origin_ = to_vec4(origin);
    std::vector<ContactMotion> table(motion_.size());
    for (size_t k = 0; k < motion_.size(); ++k) {
      const ToolMotion& m = motion_[k];
      table[k] = {to_vec4(m.from.position - origin), to_vec4(m.from.axis),
                  to_vec4(m.to.position - origin), to_vec4(m.to.axis)};
    }
    const uint64_t table_bytes = table.size() * sizeof(ContactMotion);
    reserve(ctx, motion_upload_, table_bytes, MemoryIntent::Upload, "contact motion staging");
    reserve(ctx, motion_table_, table_bytes, MemoryIntent::Device, "contact motion");
    std::memcpy(motion_upload_.mapped(), table.data(), table_bytes);
    rec.copy(motion_upload_, motion_table_, table_bytes);
    // Room for every phyxel of the broad phase (a wake can bring any of them back).
    const uint64_t capacity = std::max<size_t>(broad_list_.size(), 1);
    if (capacity > candidate_capacity_)
      candidate_capacity_ =
          static_cast<uint32_t>(std::max<uint64_t>(capacity, 2 * uint64_t{candidate_capacity_}));
    const uint64_t cap = candidate_capacity_;
    reserve(ctx, candidate_upload_, cap * sizeof(uint32_t), MemoryIntent::Upload,
            "contact candidates staging");
    reserve(ctx, candidate_list_, cap * sizeof(uint32_t), MemoryIntent::Device,
            "contact candidates");
    reserve(ctx, candidate_force_, cap * nt * sizeof(vec4), MemoryIntent::Device,
            "contact force per candidate");
    filter_candidates(rec);
    rec.barrier();
  }
  reserve(ctx, samples_buffer_, uint64_t(substeps) * nt * sizeof(vec4), MemoryIntent::Readback,
          "contact samples");
  contact_active_ = motion_steps_ > 0 && !candidates_.empty();
}

void GpuSolver::record_contact(Recorder& rec, int64_t step, float dt, const Buffer& disp) {
  const uint32_t n = static_cast<uint32_t>(candidates_.size());
  const uint32_t nt = static_cast<uint32_t>(tools_.size());
  // This substep's row of the motion table; past the chunk the tools keep the last end pose.
  const uint64_t k = motion_step_ + uint64_t(step);
  const ContactPush push{contact_origin_,
                         n,
                         dt,
                         nt,
                         static_cast<uint32_t>(std::min<uint64_t>(k, motion_steps_ - 1)),
                         k >= motion_steps_ ? 1u : 0u,
                         candidate_capacity_,
                         0u,
                         0u};
  dispatch(rec, kernels_->contact, push,
           {candidate_list_, rest_, disp, vel_, ext_, flags_, tool_shapes_, motion_table_,
            candidate_force_, contact_flag_},
           n);
  rec.barrier();
  dispatch(rec, kernels_->contact_reduce,
           ContactReducePush{n, nt, candidate_capacity_, static_cast<uint32_t>(step)},
           {candidate_force_, samples_buffer_}, nt * kernels_->contact_reduce.workgroup_size()[0]);
}

void GpuSolver::finish_contact(int64_t substeps, bool ran) {
  samples_.clear();
  if (motion_steps_ == 0) return;  // no motion yet: as the CPU, no samples
  const size_t nt = tools_.size();
  samples_.assign(size_t(substeps) * nt, ToolContactSample{});
  if (contact_active_ && ran) {
    samples_buffer_.invalidate();
    std::vector<vec4> felt(samples_.size());
    std::memcpy(felt.data(), samples_buffer_.mapped(), felt.size() * sizeof(vec4));
    for (size_t k = 0; k < felt.size(); ++k) {
      samples_[k].force = Vec3(felt[k].x, felt[k].y, felt[k].z);
      samples_[k].contacts = static_cast<uint32_t>(felt[k].w);
    }
  }
  motion_step_ += size_t(substeps);
}

}  // namespace phyxel::gpu
