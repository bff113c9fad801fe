#include "bench/bench_tools.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "bench/benches.h"
#include "bench/timing.h"
#include "compute/gpu_solver.h"
#include "engine/run/run_schedule.h"

namespace phyxel::bench {

std::unique_ptr<Solver> make_bench_solver(const std::string& device, const PhyxelSet& set,
                                          const Vec3& gravity, int threads) {
  if (device == "cpu") return make_cpu_solver(set, gravity, threads);
  gpu::ContextOptions context;
  context.device = device;
  context.validation = false;
  return make_gpu_solver(set, gravity, context);
}

std::vector<int64_t> parse_phyxel_sizes(const std::string& text, int64_t least) {
  std::vector<int64_t> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const long long v = std::strtoll(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || v < least)
      throw UsageError("phyxel bench: --sizes " + text +
                       ": expected a comma-separated list of phyxel counts (at least " +
                       std::to_string(least) + ")");
    out.push_back(v);
  }
  return out;
}

double pass_ns(const std::vector<gpu::PassTime>& passes, const std::string& name) {
  for (const gpu::PassTime& p : passes)
    if (p.name == name) return p.ns;
  return 0;
}

Scene crossing_blade_scene(int64_t size, bool blade) {
  Scene scene = bench_scene(size);
  ToolDesc t;
  t.name = "scalpel";
  t.shape.type = ToolShape::Type::Capsule;
  t.shape.radius = 0.0005;
  t.shape.length = 0.09;
  // Across the box along x at y = 0.0503 (off the lattice planes), tip at z = 0.03.
  const double y = 0.0503, z = 0.03;
  t.path = {{0.0, Vec3(-0.005, y, z), Vec3::UnitZ()},
            {0.11 / kCrossingSpeed, Vec3(0.105, y, z), Vec3::UnitZ()}};
  t.friction = 0.2;
  if (blade) {
    t.type = ToolDesc::Type::Scalpel;
    t.blade.length = 0.09;
    t.blade.edge = Vec3::UnitX();
    t.blade.reference_axis = Vec3::UnitZ();
  }
  scene.tools.push_back(t);
  return scene;
}

ToolBenchCase::ToolBenchCase(const std::string& device, int threads, Scene scene_)
    : scene(std::move(scene_)),
      set(sample_scene(scene)),
      dt(plan_time_step(scene, set).dt_stable),
      solver(make_bench_solver(device, set, scene.simulation.gravity, threads)),
      track(scene.tools, nullptr) {
  if (!scene.tools.empty())
    need(solver->tools(), *solver, "simulate tools").set_tools(contact_tools(scene.tools));
  // As run_simulation does: tearing on when a material can tear.
  if (scene.tearing_possible()) {
    need(solver->principal_stress(), *solver, "compute principal stresses")
        .set_principal_stress(true);
    need(solver->tearing(), *solver, "tear").set_tearing(true);
  }
}

void ToolBenchCase::run(int64_t steps) {
  const int64_t chunk = tool_chunk_substeps(RunOptions{}, set.size());
  for (int64_t left = steps; left > 0;) {
    const int64_t n = std::min(left, chunk);
    advance_with_tools(*solver, track, done, n, 1, dt);
    done += n;
    left -= n;
  }
}

std::vector<gpu::PassTime> ToolBenchCase::profile(int64_t steps) {
  auto* g = dynamic_cast<gpu::GpuSolver*>(solver.get());
  if (g == nullptr) return {};
  if (!track.empty()) g->set_tool_motion(track.motions(done, steps, dt));
  std::vector<gpu::PassTime> passes = g->profile(steps, dt);
  if (!track.empty()) g->tool_samples();
  done += steps;
  return passes;
}

StepSeconds interleaved_step_seconds(ToolBenchCase& a, ToolBenchCase& b, int64_t steps,
                                     int64_t repeats) {
  const std::vector<Timing> t =
      time_interleaved({[&] { a.run(steps); }, [&] { b.run(steps); }}, repeats);
  return {t[0].median / double(steps), t[1].median / double(steps)};
}

int64_t crossing_entry_steps(double dt) {
  return static_cast<int64_t>(std::ceil(0.015 / kCrossingSpeed / dt));
}

}  // namespace phyxel::bench
