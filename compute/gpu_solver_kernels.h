// The GPU solver's pipelines (one per shader of compute/shaders/{nbr,scan,solver,tool}_*.comp) and
// the exclusive prefix sum built from two of them. Private to compute/gpu_solver*.cpp.
#pragma once

#include <cstdint>
#include <vector>

#include "compute/pipeline.h"
#include "compute/shaders/layout.h"

namespace phyxel::gpu {

class SolverKernels {
 public:
  // `pairs_split`: the pipelines that touch pairs read a second part of the neighbour index
  // and the pair weights past the first `pairs_lo` pairs (PairBuffer; specialization
  // constants 0 and 1 of pair_buffers.glsl).
  SolverKernels(Context& ctx, bool pairs_split, uint32_t pairs_lo);
  // Remakes the pipelines that touch pairs for a second part after `pairs_lo` pairs (the
  // neighbour search found more pairs than one part holds, though the lattice bound said not).
  void split_pairs(Context& ctx, uint32_t pairs_lo);
  bool pairs_split() const { return pairs_split_; }

  Pipeline nbr_cells;       // layout::NbrPush; kNbrCells* bindings
  Pipeline nbr_scatter;     // layout::NbrPush; kNbrScatter* bindings
  Pipeline nbr_pairs;       // layout::NbrPush; kNbrPairs* bindings; support test in float
  Pipeline nbr_pairs_f64;   // the same in double; empty where the device has no shaderFloat64
  Pipeline scan_block;      // layout::ScanPush; kScan* bindings
  Pipeline scan_add;        // layout::ScanPush; kScanAdd* bindings
  Pipeline precompute;      // layout::PrecomputePush; kPrecompute* bindings
  Pipeline kick_drift;      // layout::StepPush; kKickDrift* bindings (over the force list)
  Pipeline stress;          // layout::StepPush; kStress* bindings (over the stress list)
  Pipeline force;           // layout::StepPush; kForce* bindings (over the force list)
  Pipeline energy;          // layout::StepPush; kEnergy* bindings
  Pipeline reduce;          // layout::ReducePush; kReduce* bindings
  Pipeline check;           // layout::CheckPush; kCheck* bindings
  Pipeline von_mises;       // layout::StepPush; kEnergy* bindings
  Pipeline force_tear;      // layout::ForceTearPush; kForce*, kForceTear* bindings
  Pipeline force_contact;   // layout::ForceTearPush; kForce*, kForceContact* bindings
  Pipeline max_norm;        // layout::MaxNormPush; kMaxNorm* bindings
  Pipeline motion;          // layout::MotionPush; kMotion* bindings
  Pipeline contact;         // layout::ContactPush; kContact* bindings (over the candidates)
  Pipeline contact_reduce;  // layout::ContactReducePush; kContactReduce* bindings
  Pipeline broad_phase;     // layout::BroadPhasePush; kBroad* bindings
  Pipeline broad_scan;      // layout::BroadPhasePush; kBroadScan* bindings
  Pipeline sever;           // layout::SeverPush; kSever* bindings (over the candidates)
  Pipeline sever_sided;     // the same where a blade keeps sides (a threshold > 0)
  // Both beside the stress pass (kSeverBesideStressPipeline: their own name for validation).
  Pipeline sever_beside, sever_sided_beside;
  Pipeline resist;  // layout::ResistPush; kResist* bindings (over the candidates)
  Pipeline grasp;   // layout::GraspPush; kGrasp* bindings (candidates, grip or a tool)
  Pipeline near;    // layout::NearPush; kNear* bindings (aspiration's reads)
  Pipeline edit;    // layout::EditPush; kEdit* bindings (remove_phyxels)

 private:
  void make_pair_pipelines(Context& ctx);
  bool pairs_split_ = false;
  uint32_t pairs_lo_ = 0;
};

// Exclusive prefix sum of a uint array on the GPU: dst[i] = sum of src[k] for k < i, for
// i < count, where src has input_count <= count elements (dst[input_count] is then the total
// when count = input_count + 1). Holds the block-sum buffers of every level for one count.
class PrefixScan {
 public:
  PrefixScan(Context& ctx, const SolverKernels& kernels, uint32_t count);

  // Records the scan (several dispatches separated by barriers). Put a barrier between the
  // pass that writes src and this, and between this and the pass that reads dst.
  void record(Recorder& rec, const Buffer& src, uint32_t input_count, const Buffer& dst) const;

 private:
  struct Level {
    uint32_t count = 0;   // elements scanned at this level
    uint32_t blocks = 0;  // its block sums
    Buffer sums;          // block totals
    Buffer scanned;       // their exclusive scan (when blocks > 1)
  };
  void record_level(Recorder& rec, size_t level, const Buffer& src, uint32_t input_count,
                    const Buffer& dst) const;

  const SolverKernels* kernels_;
  std::vector<Level> levels_;
};

}  // namespace phyxel::gpu
