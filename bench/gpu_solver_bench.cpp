#include "bench/gpu_solver_bench.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

#include "bench/timing.h"

namespace phyxel::bench {

using gpu::Context;
using gpu::GpuSolver;
using gpu::GpuSolverOptions;

GpuBenchResult bench_gpu_solver(Context& ctx, const PhyxelSet& set, const Vec3& gravity, double dt,
                                double copy_gb_per_s, const GpuBenchOptions& options) {
  GpuBenchResult r;
  r.phyxels = set.size();
  r.copy_gb_per_s = copy_gb_per_s;
  const bool stored = options.pair_weights == GpuSolverOptions::PairWeights::Stored;
  r.pair_weights = stored ? "stored" : "auto";
  GpuSolverOptions solver_options;
  solver_options.pair_weights = options.pair_weights;
  solver_options.lanes = options.lanes;
  {
    GpuSolver solver(ctx, set, gravity, solver_options);
    r.device = solver.device();
    const auto n = static_cast<uint32_t>(set.size());
    r.lanes = std::to_string(solver.lanes_for(GpuSolver::Gather::Stress, n)) + "/" +
              std::to_string(solver.lanes_for(GpuSolver::Gather::Force, n));
    r.neighbours_per_phyxel = double(solver.pair_count()) / double(set.size());
    r.gpu_bytes_per_phyxel = double(ctx.allocated_bytes()) / double(set.size());
    r.bytes_per_phyxel_step = solver.bytes_per_phyxel_step();

    // Warm-up (pipelines, clocks, caches) and the probe that sizes a repeat.
    solver.advance(20, dt);
    const auto t0 = std::chrono::steady_clock::now();
    solver.advance(50, dt);
    solver.finish();
    const double probe = seconds_since(t0) / 50;
    r.steps_per_repeat =
        options.steps > 0 ? options.steps : std::clamp<int64_t>(int64_t(0.5 / probe), 50, 200000);
    r.repeats = options.repeats;
    const Timing t = time_repeats(
        [&] {
          solver.advance(r.steps_per_repeat, dt);
          solver.finish();
        },
        options.repeats);
    for (const double s : t.seconds) r.seconds_per_step.push_back(s / double(r.steps_per_repeat));
    r.median_seconds_per_step = t.median / double(r.steps_per_repeat);
    r.phyxel_steps_per_second = double(set.size()) / r.median_seconds_per_step;
    const double bandwidth = copy_gb_per_s * 1e9;
    r.roofline_phyxel_steps_per_second = bandwidth / r.bytes_per_phyxel_step;
    r.roofline_fraction = r.phyxel_steps_per_second / r.roofline_phyxel_steps_per_second;
    r.passes = solver.profile(10, dt);
    r.finite = solver.first_non_finite() < 0;
    r.ill_conditioned = solver.regularised_count();
  }

  // Accuracy: fresh solvers, the same steps on the GPU and on the CPU reference (double).
  if (options.check_steps < 0) {  // none (sizes whose CPU reference would not fit the host)
    r.check_steps = 0;
    r.error_over_extent = r.error_over_max_displacement = r.max_displacement =
        std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  r.check_steps = options.check_steps > 0 ? options.check_steps : (set.size() > 200000 ? 20 : 100);
  GpuSolver gpu(ctx, set, gravity, solver_options);
  gpu.advance(r.check_steps, dt);
  const PointState g = gpu.read_state(false);
  CpuSolver<double> cpu(set, gravity);
  cpu.set_threads(options.cpu_threads);
  for (int64_t s = 0; s < r.check_steps; ++s) cpu.step(dt);
  double err = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    err = std::max(err, (g.displacement[i] - cpu.displacement()[i]).norm());
    r.max_displacement = std::max(r.max_displacement, cpu.displacement()[i].norm());
  }
  Eigen::AlignedBox3d box;
  for (const Vec3& x : set.rest) box.extend(x);
  r.error_over_extent = err / box.sizes().maxCoeff();
  r.error_over_max_displacement = r.max_displacement > 0 ? err / r.max_displacement : 0.0;
  return r;
}

}  // namespace phyxel::bench
