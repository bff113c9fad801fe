#include "compute/gpu_solver_kernels.h"

#include "compute/instance.h"

#include <cstdint>

#include "phyxel_spv/nbr_cells.spv.h"
#include "phyxel_spv/nbr_pairs.spv.h"
#include "phyxel_spv/nbr_pairs_f64.spv.h"
#include "phyxel_spv/nbr_scatter.spv.h"
#include "phyxel_spv/scan_add.spv.h"
#include "phyxel_spv/scan_block.spv.h"
#include "phyxel_spv/solver_check.spv.h"
#include "phyxel_spv/solver_edit.spv.h"
#include "phyxel_spv/solver_energy.spv.h"
#include "phyxel_spv/solver_force.spv.h"
#include "phyxel_spv/solver_force_contact.spv.h"
#include "phyxel_spv/solver_force_tear.spv.h"
#include "phyxel_spv/solver_kick_drift.spv.h"
#include "phyxel_spv/solver_max_norm.spv.h"
#include "phyxel_spv/solver_motion.spv.h"
#include "phyxel_spv/solver_near.spv.h"
#include "phyxel_spv/solver_precompute.spv.h"
#include "phyxel_spv/solver_reduce.spv.h"
#include "phyxel_spv/solver_stress.spv.h"
#include "phyxel_spv/solver_von_mises.spv.h"
#include "phyxel_spv/tool_broad_phase.spv.h"
#include "phyxel_spv/tool_broad_scan.spv.h"
#include "phyxel_spv/tool_contact.spv.h"
#include "phyxel_spv/tool_contact_reduce.spv.h"
#include "phyxel_spv/tool_grasp.spv.h"
#include "phyxel_spv/tool_resist.spv.h"
#include "phyxel_spv/tool_sever.spv.h"

namespace phyxel::gpu {

using namespace layout;

SolverKernels::SolverKernels(Context& ctx, bool pairs_split, uint32_t pairs_lo)
    : nbr_cells(ctx, PHYXEL_SHADER(nbr_cells), 6, sizeof(NbrPush)),
      nbr_scatter(ctx, PHYXEL_SHADER(nbr_scatter), 4, sizeof(NbrPush)),
      scan_block(ctx, PHYXEL_SHADER(scan_block), 3, sizeof(ScanPush)),
      scan_add(ctx, PHYXEL_SHADER(scan_add), 2, sizeof(ScanPush)),
      kick_drift(ctx, PHYXEL_SHADER(solver_kick_drift), 8, sizeof(StepPush)),
      reduce(ctx, PHYXEL_SHADER(solver_reduce), 2, sizeof(ReducePush)),
      check(ctx, PHYXEL_SHADER(solver_check), 3, sizeof(CheckPush)),
      max_norm(ctx, PHYXEL_SHADER(solver_max_norm), 4, sizeof(MaxNormPush)),
      motion(ctx, PHYXEL_SHADER(solver_motion), 4, sizeof(MotionPush)),
      contact(ctx, PHYXEL_SHADER(tool_contact), 21, sizeof(ContactPush)),
      contact_reduce(ctx, PHYXEL_SHADER(tool_contact_reduce), 8, sizeof(ContactReducePush)),
      broad_phase(ctx, PHYXEL_SHADER(tool_broad_phase), 8, sizeof(BroadPhasePush)),
      broad_scan(ctx, PHYXEL_SHADER(tool_broad_scan), 2, sizeof(BroadPhasePush)),
      grasp(ctx, PHYXEL_SHADER(tool_grasp), 14, sizeof(GraspPush)),
      near(ctx, PHYXEL_SHADER(solver_near), 6, sizeof(NearPush)),
      pairs_split_(pairs_split),
      pairs_lo_(pairs_lo) {
  make_pair_pipelines(ctx);
}

void SolverKernels::split_pairs(Context& ctx, uint32_t pairs_lo) {
  pairs_split_ = true;
  pairs_lo_ = pairs_lo;
  make_pair_pipelines(ctx);
}

void SolverKernels::make_pair_pipelines(Context& ctx) {
  const std::vector<uint32_t> spec = {pairs_split_ ? 1u : 0u, pairs_lo_};
  auto make = [&](const ShaderCode& code, uint32_t bindings, uint32_t push) {
    return Pipeline(ctx, code, bindings, push, {}, spec);
  };
  nbr_pairs = make(PHYXEL_SHADER(nbr_pairs), 13, sizeof(NbrPush));
  if (ctx.float64()) nbr_pairs_f64 = make(PHYXEL_SHADER(nbr_pairs_f64), 13, sizeof(NbrPush));
  precompute = make(PHYXEL_SHADER(solver_precompute), 12, sizeof(PrecomputePush));
  stress = make(PHYXEL_SHADER(solver_stress), 16, sizeof(StressPush));
  force = make(PHYXEL_SHADER(solver_force), 15, sizeof(StepPush));
  energy = make(PHYXEL_SHADER(solver_energy), 13, sizeof(StepPush));
  von_mises = make(PHYXEL_SHADER(solver_von_mises), 13, sizeof(StepPush));
  force_tear = make(PHYXEL_SHADER(solver_force_tear), 29, sizeof(ForceTearPush));
  force_contact = make(PHYXEL_SHADER(solver_force_contact), 28, sizeof(ForceTearPush));
  sever =
      Pipeline(ctx, PHYXEL_SHADER(tool_sever), 23, sizeof(SeverPush), {}, {spec[0], spec[1], 0u});
  sever_sided =
      Pipeline(ctx, PHYXEL_SHADER(tool_sever), 23, sizeof(SeverPush), {}, {spec[0], spec[1], 1u});
  ShaderCode beside = PHYXEL_SHADER(tool_sever);
  beside.name = kSeverBesideStressPipeline;
  sever_beside = Pipeline(ctx, beside, 23, sizeof(SeverPush), {}, {spec[0], spec[1], 0u});
  sever_sided_beside = Pipeline(ctx, beside, 23, sizeof(SeverPush), {}, {spec[0], spec[1], 1u});
  resist = make(PHYXEL_SHADER(tool_resist), 18, sizeof(ResistPush));
  edit = make(PHYXEL_SHADER(solver_edit), 8, sizeof(EditPush));
}

namespace {

uint32_t blocks_of(uint32_t count) {
  return (count + kScanBlock - 1) / kScanBlock;
}

}  // namespace

PrefixScan::PrefixScan(Context& ctx, const SolverKernels& kernels, uint32_t count)
    : kernels_(&kernels) {
  uint32_t n = count;
  while (true) {
    Level level;
    level.count = n;
    level.blocks = blocks_of(n);
    level.sums = Buffer(ctx, uint64_t{level.blocks} * sizeof(uint32_t), MemoryIntent::Device,
                        "scan block sums");
    if (level.blocks > 1) {
      level.scanned = Buffer(ctx, uint64_t{level.blocks} * sizeof(uint32_t), MemoryIntent::Device,
                             "scan block prefixes");
    }
    const uint32_t next = level.blocks;
    levels_.push_back(std::move(level));
    if (next <= 1) break;
    n = next;
  }
}

void PrefixScan::record(Recorder& rec, const Buffer& src, uint32_t input_count,
                        const Buffer& dst) const {
  record_level(rec, 0, src, input_count, dst);
}

void PrefixScan::record_level(Recorder& rec, size_t index, const Buffer& src, uint32_t input_count,
                              const Buffer& dst) const {
  const Level& level = levels_[index];
  if (level.count == 0) return;
  const uint32_t threads = kernels_->scan_block.workgroup_size()[0];
  dispatch(rec, kernels_->scan_block, ScanPush{level.count, input_count},
           {{"Src", src}, {"Dst", dst}, {"Sums", level.sums}}, level.blocks * threads);
  if (level.blocks <= 1) return;
  rec.barrier();
  record_level(rec, index + 1, level.sums, level.blocks, level.scanned);
  rec.barrier();
  dispatch(rec, kernels_->scan_add, ScanPush{level.count, level.count},
           {{"Dst", dst}, {"Sums", level.scanned}}, level.count);
}

}  // namespace phyxel::gpu
