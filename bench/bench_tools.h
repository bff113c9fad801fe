// Pieces the benches with tools share (bench_haptics.cpp, bench_cutting.cpp,
// bench_tearing.cpp, bench_surgery.cpp; make_bench_solver also bench_skips.cpp): a solver by
// device name, a box scene with its tools stepped as the run loop steps them, per-pass GPU
// timestamps, and small helpers.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "compute/timing.h"
#include "engine/run/simulation.h"

namespace phyxel::bench {

// "cpu": the CPU reference with `threads` (0: all cores); anything else: the GPU solver on
// that device (validation off).
std::unique_ptr<Solver> make_bench_solver(const std::string& device, const PhyxelSet& set,
                                          const Vec3& gravity, int threads);

// A comma-separated list of phyxel counts, each at least `least` (UsageError otherwise).
std::vector<int64_t> parse_phyxel_sizes(const std::string& text, int64_t least);
// The time of the pass `name` (ns), 0 when absent.
double pass_ns(const std::vector<gpu::PassTime>& passes, const std::string& name);

// The box of bench_scene(size) crossed along x at kCrossingSpeed by a vertical capsule of
// radius 0.5 mm (its tip 3 cm above the base, 7 cm of it in the box): a scalpel whose blade is
// the capsule's length when `blade`, else the same body as a probe (bench_cutting.cpp,
// bench_tearing.cpp).
constexpr double kCrossingSpeed = 0.5;  // m/s
Scene crossing_blade_scene(int64_t size, bool blade);

// A scene, its phyxels, its stable step and a solver with the scene's tools, stepped in chunks
// of the run loop's size (tool_chunk_substeps for its phyxels): one broad phase and one submit
// per chunk, as a run that is not paced to the wall clock does.
struct ToolBenchCase {
  ToolBenchCase(const std::string& device, int threads, Scene scene);
  void run(int64_t steps);
  // GPU only: the per-pass timestamps of `steps` steps in one submit (empty on the CPU).
  std::vector<gpu::PassTime> profile(int64_t steps);

  Scene scene;
  PhyxelSet set;
  double dt;
  std::unique_ptr<Solver> solver;
  ToolTrack track;
  int64_t done = 0;
};

// Wall seconds per step of `a` and of `b`, `steps` steps per timed repeat, the two interleaved
// (time_interleaved: a busy machine slows both alike); the medians of the repeats.
struct StepSeconds {
  double a, b;
};
StepSeconds interleaved_step_seconds(ToolBenchCase& a, ToolBenchCase& b, int64_t steps,
                                     int64_t repeats);
// Steps for the blade of crossing_blade_scene to enter its box (1 cm of travel).
int64_t crossing_entry_steps(double dt);

}  // namespace phyxel::bench
