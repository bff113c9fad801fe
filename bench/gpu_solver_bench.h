// Measurements of the GPU solver for `phyxel bench --device gpu` (bench_scale.cpp formats
// them): median time per step, GPU memory per phyxel, the counted bytes per phyxel-step
// against the device's measured copy bandwidth (the roofline), per-pass timestamps, and the
// error against the CPU double-precision reference after the same steps.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/gpu_solver.h"

namespace phyxel::bench {

struct GpuBenchOptions {
  int64_t steps = 0;        // steps per timed repeat; 0: about 0.5 s of work
  int64_t repeats = 5;      // the median is reported
  int64_t check_steps = 0;  // steps of the CPU comparison; 0: 100, or 20 above 200k phyxels;
                            // negative: no comparison (the error fields stay NaN)
  int cpu_threads = 0;      // of the CPU reference; 0: all cores
  gpu::GpuSolverOptions::PairWeights pair_weights = gpu::GpuSolverOptions::PairWeights::Auto;
  uint32_t lanes = 0;  // GpuSolverOptions::lanes (0: auto)
};

struct GpuBenchResult {
  std::string device;
  std::string pair_weights;  // "auto" or "stored" (gpu::GpuSolverOptions::PairWeights)
  size_t phyxels = 0;
  std::string lanes;  // invocations per phyxel of the stress and force passes, as run ("1/2")
  std::vector<double> seconds_per_step;  // of each timed repeat, in order
  double neighbours_per_phyxel = 0;
  int64_t steps_per_repeat = 0;
  int64_t repeats = 0;
  double median_seconds_per_step = 0;
  double phyxel_steps_per_second = 0;
  double gpu_bytes_per_phyxel = 0;   // Context::allocated_bytes() / phyxels
  double bytes_per_phyxel_step = 0;  // counted traffic of the step passes
  double copy_gb_per_s = 0;          // measure_copy_bandwidth (read + write)
  double roofline_phyxel_steps_per_second = 0;
  double roofline_fraction = 0;
  std::vector<gpu::PassTime> passes;  // median ns per pass of a profiled run
  int64_t check_steps = 0;
  double error_over_extent = 0;            // max |u_gpu - u_cpu| / largest side of the bounds
  double error_over_max_displacement = 0;  // max |u_gpu - u_cpu| / max |u_cpu|
  double max_displacement = 0;             // max |u_cpu| after check_steps
  bool finite = true;
  // Moment matrices the GPU's precompute found ill-conditioned and regularised: 0 for the bench
  // box (every phyxel of a lattice has a full neighbourhood). A check that needs no CPU
  // reference: at sizes run without one (--no-check), pairs read wrong show here.
  size_t ill_conditioned = 0;
};

// Times the GPU solver on `set` with step `dt` (ctx is shared between sizes; the bandwidth is
// measured once by the caller with measure_copy_bandwidth).
GpuBenchResult bench_gpu_solver(gpu::Context& ctx, const PhyxelSet& set, const Vec3& gravity,
                                double dt, double copy_gb_per_s, const GpuBenchOptions& options);

}  // namespace phyxel::bench
