// phyxel bench: solver speed on elastic boxes of several sizes.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/bench_accuracy.h"
#include "app/commands.h"
#include "app/options.h"
#include "engine/simulation.h"

namespace phyxel::app {
namespace {

constexpr const char* kBenchHelp =
    "usage: phyxel bench [options]\n"
    "\n"
    "Times the solver on an elastic box clamped at its base under gravity, for each size and\n"
    "thread count: median seconds per step over repeats and phyxel-steps per second.\n"
    "\n"
    "options:\n"
    "  --device cpu          solver device\n"
    "  --sizes LIST          approximate phyxel counts (default 1000,10000,100000)\n"
    "  --threads LIST        CPU thread counts (default 1,2)\n"
    "  --steps N             steps per timed repeat (default: about 0.5 s of work)\n"
    "  --repeats N           timed repeats, the median is reported (default 5)\n"
    "  --json FILE           also write the rows as JSON";

std::vector<int64_t> parse_list(const std::string& text, const std::string& option) {
  std::vector<int64_t> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const long long v = std::strtoll(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || v <= 0)
      throw UsageError("phyxel bench: " + option + " " + text +
                       ": expected a comma-separated list of positive integers");
    out.push_back(v);
  }
  return out;
}

// A cube of about `phyxels` points: 0.1 m on a side, clamped at z = 0, soft tissue material.
Scene bench_scene(int64_t phyxels) {
  const int per_side = std::max(2, static_cast<int>(std::lround(std::cbrt(double(phyxels)))));
  const double side = 0.1, spacing = side / (per_side - 1);
  Scene scene;
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  ObjectDesc box;
  box.name = "box";
  box.shape.type = Shape::Type::Box;
  box.shape.min = Vec3::Zero();
  box.shape.max = Vec3::Constant(side);
  box.spacing = spacing;
  box.support_radius = 2 * spacing;
  box.material = {1e5, 0.3, 1000, 1.0, std::nullopt, 0.05};
  Shape base;
  base.type = Shape::Type::Box;
  base.min = Vec3(-1, -1, -1);
  base.max = Vec3(1, 1, 0.5 * spacing);
  box.fixed.push_back(base);
  scene.objects.push_back(box);
  scene.simulation.dt = 1;  // replaced by the stable step below
  return scene;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int bench_command(const Args& args) {
  if (std::find(args.begin(), args.end(), "--accuracy") != args.end()) {
    return bench_accuracy(args, [](const std::string& device, int threads) -> SolverFactory {
      if (device != "cpu")
        throw UsageError("phyxel bench --accuracy: --device " + device + ": allowed cpu");
      return [threads](const PhyxelSet& set, const Vec3& g) {
        return make_cpu_solver(set, g, threads);
      };
    });
  }
  OptionParser opts("bench", args);
  if (opts.flag("--help")) {
    std::puts(kBenchHelp);
    return 0;
  }
  const std::string device = opts.value("--device", "cpu");
  const auto sizes = parse_list(opts.value("--sizes", "1000,10000,100000"), "--sizes");
  const auto threads = parse_list(opts.value("--threads", "1,2"), "--threads");
  const int64_t fixed_steps = opts.integer("--steps", 0, 0, 1 << 30);
  const int64_t repeats = opts.integer("--repeats", 5, 1, 1000);
  const std::string json_file = opts.value("--json", "");
  opts.finish();
  if (device != "cpu")
    throw UsageError("phyxel bench: --device " + device +
                     ": this build has only the CPU reference solver; use --device cpu");

  nlohmann::json rows = nlohmann::json::array();
  std::printf("%-26s %9s %8s %12s %16s %10s\n", "device", "phyxels", "nbr/phx", "s/step",
              "phyxel-steps/s", "steps");
  for (const int64_t size : sizes) {
    Scene scene = bench_scene(size);
    const PhyxelSet set = sample_scene(scene);
    scene.simulation.dt = plan_time_step(scene, set).dt_stable;
    for (const int64_t t : threads) {
      auto solver = make_cpu_solver(set, scene.simulation.gravity, static_cast<int>(t));
      const double nbr = double(solver->neighbours().index.size()) / double(set.size());
      // Steps per repeat: fixed, or about 0.5 s of work from a one-step probe.
      int64_t steps = fixed_steps;
      if (steps == 0) {
        const auto t0 = std::chrono::steady_clock::now();
        solver->advance(1, scene.simulation.dt);
        const double one =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        steps = std::clamp<int64_t>(static_cast<int64_t>(0.5 / std::max(one, 1e-9)), 3, 100000);
      }
      std::vector<double> per_step;
      for (int64_t r = 0; r < repeats; ++r) {
        const auto t0 = std::chrono::steady_clock::now();
        solver->advance(steps, scene.simulation.dt);
        const double s =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        per_step.push_back(s / double(steps));
      }
      const double med = median(per_step);
      const double rate = double(set.size()) / med;
      std::printf("%-26s %9zu %8.1f %12.4g %16.4g %10lld\n", solver->device().c_str(), set.size(),
                  nbr, med, rate, static_cast<long long>(steps));
      rows.push_back({{"device", solver->device()},
                      {"threads", t},
                      {"phyxels", set.size()},
                      {"neighbours_per_phyxel", nbr},
                      {"median_seconds_per_step", med},
                      {"phyxel_steps_per_second", rate},
                      {"steps_per_repeat", steps},
                      {"repeats", repeats},
                      {"finite", solver->first_non_finite() < 0}});
    }
  }
  if (!json_file.empty()) {
    std::ofstream out(json_file);
    out << rows.dump(2) << "\n";
    if (!out) throw std::runtime_error("cannot write " + json_file);
  }
  return 0;
}

}  // namespace phyxel::app
