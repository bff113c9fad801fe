// phyxel bench --skips: what pass selection saves on real scenes (fixed-only regions skipped,
// sleeping objects skipped), as median seconds per step with and without it, on the CPU
// reference or (--device gpu, gpu:N, a name) the GPU solver.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench/bench_tools.h"
#include "bench/benches.h"
#include "bench/timing.h"
#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"

namespace phyxel::bench {
namespace {

double median_step_seconds(Solver& solver, double dt, int64_t steps, int repeats) {
  const auto work = [&] {
    solver.advance(steps, dt);
    solver.finish();
  };
  return time_repeats(work, repeats).median / double(steps);
}

}  // namespace

int bench_skips(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--skips");
  std::string scenes_text =
      opts.value("--scenes", "scenes/brain_tumour.json,scenes/breast_tumour.json,scenes/beam.json");
  const int64_t steps = opts.integer("--steps", 200, 1, 1 << 30);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string device = opts.value("--device", "cpu");  // cpu, gpu, gpu:N or a name
  const std::string json_file = opts.value("--json", "");
  // Finer versions of the scenes: spacing and support radius divided by this (phyxels x K^3).
  const double refine = opts.number("--refine", 1, 1, kMaxRefine);
  opts.finish();
  std::vector<std::string> scenes;
  std::stringstream ss(scenes_text);
  for (std::string item; std::getline(ss, item, ',');) scenes.push_back(item);

  nlohmann::json rows = nlohmann::json::array();
  for (const std::string& file : scenes) {
    Scene scene = load_scene(file);
    refine_scene(scene, refine);
    const PhyxelSet set = sample_scene(scene);
    const double dt = plan_time_step(scene, set).dt_stable;
    size_t fixed = 0;
    for (uint32_t f : set.flags) fixed += (f & kFixed) ? 1 : 0;
    auto solver = make_bench_solver(device, set, scene.simulation.gravity, threads);
    if (rows.empty()) {
      std::printf("%s\n", solver->device().c_str());
      std::printf("%-28s %8s %8s %12s %12s %12s %8s %12s\n", "scene", "phyxels", "fixed",
                  "all s/step", "skip s/step", "saved", "stress", "asleep s/step");
    }
    solver->advance(5, dt);  // warm-up (GPU clocks, first submits)
    PassSelection& passes = need(solver->pass_selection(), *solver, "select passes");
    passes.set_pass_selection(false);
    const double all = median_step_seconds(*solver, dt, steps, 5);
    passes.set_pass_selection(true);
    const double skip = median_step_seconds(*solver, dt, steps, 5);
    const size_t stress = passes.stress_pass_size();
    for (uint32_t o = 0; o < set.objects.size(); ++o) passes.set_object_awake(o, false);
    const double asleep = median_step_seconds(*solver, dt, steps, 5);
    std::printf("%-28s %8zu %8zu %12.4g %12.4g %11.1f%% %8zu %12.4g\n", file.c_str(), set.size(),
                fixed, all, skip, 100 * (1 - skip / all), stress, asleep);
    rows.push_back({{"scene", file},
                    {"phyxels", set.size()},
                    {"fixed", fixed},
                    {"device", solver->device()},
                    {"seconds_per_step_no_skip", all},
                    {"seconds_per_step_skip", skip},
                    {"stress_pass_phyxels", stress},
                    {"seconds_per_step_asleep", asleep},
                    {"steps", steps},
                    {"repeats", 5}});
  }
  write_json_file(json_file, rows);
  return 0;
}

}  // namespace phyxel::bench
