// phyxel bench --tearing: what tearing costs per step (the largest principal stress of every
// stressed phyxel, the pair criterion, the severing and the precompute of the touched phyxels)
// and the step rate while the tissue tears, on boxes of several sizes that a thin probe
// ploughs through (docs/tearing.md). Each size runs twice, interleaved: the box without a
// tear_stress (no tearing pass runs) and with one (the tissue tears around the probe); the
// wall-time difference is tearing's cost, and on a GPU the per-pass timestamps give the
// principal-stress and tear passes alone. Writes a table on stdout and, with --out DIR,
// DIR/tearing.json.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "bench/bench_tools.h"
#include "bench/benches.h"
#include "bench/timing.h"

namespace phyxel::bench {
namespace {

constexpr const char* kTearingHelp =
    "usage: phyxel bench --tearing [options]\n"
    "\n"
    "An elastic box per size (0.1 m, E 100 kPa, clamped at its base) that a probe (a capsule\n"
    "of radius 5 mm, 7 cm of it in the box) ploughs through at 0.5 m/s. Per size:\n"
    "seconds per step without tearing and with tear_stress T (the tissue tears around the\n"
    "probe), interleaved, the median of the repeats; tearing's cost per step and share of the\n"
    "step, the step rate while tearing, pairs torn per step; GPU rows add the principal-stress\n"
    "and tear passes' own time per step (timestamps).\n"
    "\n"
    "options:\n"
    "  --device D        cpu (default), gpu, gpu:N or part of a GPU's name\n"
    "  --sizes LIST      box sizes in phyxels (default 10000,100000 on the CPU,\n"
    "                    10000,100000,1000000 on a GPU)\n"
    "  --tear-stress T   Pa (default 12000)\n"
    "  --steps N         steps per timed repeat (default 64)\n"
    "  --repeats N       timed repeats, the median is reported (default 5)\n"
    "  --threads N       CPU solver threads (default: all cores)\n"
    "  --out DIR         write DIR/tearing.json";

constexpr double kTearingProbeRadius = 0.005;  // m

Scene tearing_scene(int64_t size, std::optional<double> tear_stress) {
  Scene scene = crossing_blade_scene(size, false);
  // A probe thick enough to load the tissue it passes (the scalpel bench's 0.5 mm capsule slips
  // between the phyxels of the coarse boxes and stresses nothing).
  scene.tools.front().name = "probe";
  scene.tools.front().shape.radius = kTearingProbeRadius;
  scene.objects.front().material.tear_stress = tear_stress;
  return scene;
}

nlohmann::json tearing_row(const std::string& device, int threads, int64_t size, double tear_stress,
                           int64_t steps, int64_t repeats) {
  ToolBenchCase intact(device, threads, tearing_scene(size, std::nullopt)),
      tearing(device, threads, tearing_scene(size, tear_stress));
  // Warm-up: the probe enters the box.
  const int64_t enter = crossing_entry_steps(tearing.dt);
  intact.run(enter);
  tearing.run(enter);
  Cutting& log = need(tearing.solver->cutting(), *tearing.solver, "tear");
  const size_t torn_before = log.severed_pairs();
  const auto [s_intact, s_tearing] = interleaved_step_seconds(intact, tearing, steps, repeats);
  const double torn_per_step = double(log.severed_pairs() - torn_before) / double(steps * repeats);
  nlohmann::json row = {
      {"device", tearing.solver->device()},
      {"phyxels", tearing.set.size()},
      {"dt", tearing.dt},
      {"tear_stress", tear_stress},
      {"steps", steps},
      {"repeats", repeats},
      {"step_ms_intact", s_intact * 1e3},
      {"step_ms_tearing", s_tearing * 1e3},
      {"tear_ms_per_step", (s_tearing - s_intact) * 1e3},
      {"tear_share_percent", 100 * (s_tearing - s_intact) / std::max(s_tearing, 1e-30)},
      {"steps_per_s_tearing", 1 / std::max(s_tearing, 1e-30)},
      {"torn_per_step", torn_per_step},
      {"torn_total", log.severed_pairs()},
      {"finite_intact", intact.solver->first_non_finite() < 0},
      {"finite_tearing", tearing.solver->first_non_finite() < 0}};
  row["finite"] = row["finite_intact"].get<bool>() && row["finite_tearing"].get<bool>();
  const std::vector<gpu::PassTime> passes = tearing.profile(32);
  if (!passes.empty()) {
    const std::vector<gpu::PassTime> intact_passes = intact.profile(32);
    // The principal stress rides the stress pass: its cost is what that pass gains.
    const double principal_ns = pass_ns(passes, "stress") - pass_ns(intact_passes, "stress");
    row["gpu_principal_us"] = principal_ns * 1e-3;
    // The tear test rides the force pass (force+tear), after the dirty list's reset where
    // the substep needs one: its cost is what those gain on the intact force pass.
    const double tear_ns = pass_ns(passes, "force+tear") + pass_ns(passes, "tear: reset") -
                           pass_ns(intact_passes, "force");
    row["gpu_tear_us"] = tear_ns * 1e-3;
    row["gpu_tear_update_us"] = (principal_ns + tear_ns) * 1e-3;
    // Every pass of a step (medians per pass), with and without tearing: the GPU's share of
    // the wall time per step; the rest is the host's and waiting.
    const auto step_us = [](const std::vector<gpu::PassTime>& p) {
      double ns = 0;
      for (const gpu::PassTime& t : p)
        if (t.name != "kick_drift") ns += t.ns;
      return ns * 1e-3;
    };
    row["gpu_step_us_tearing"] = step_us(passes);
    row["gpu_step_us_intact"] = step_us(intact_passes);
    nlohmann::json all = nlohmann::json::object();
    for (const gpu::PassTime& t : passes) all[t.name] = t.ns * 1e-3;
    row["gpu_pass_us_tearing"] = all;
  }
  return row;
}

void print_row(const nlohmann::json& r) {
  std::printf("%-40.40s %9lld %10.4g %10.4g %10.4g %8.1f%% %10.0f %9.1f",
              r["device"].get<std::string>().c_str(), r["phyxels"].get<long long>(),
              r["step_ms_intact"].get<double>(), r["step_ms_tearing"].get<double>(),
              r["tear_ms_per_step"].get<double>(), r["tear_share_percent"].get<double>(),
              r["steps_per_s_tearing"].get<double>(), r["torn_per_step"].get<double>());
  if (r.contains("gpu_tear_update_us"))
    std::printf(" %9.1f %9.1f %9.1f %9.1f", r["gpu_principal_us"].get<double>(),
                r["gpu_tear_us"].get<double>(), r["gpu_step_us_intact"].get<double>(),
                r["gpu_step_us_tearing"].get<double>());
  if (!r["finite"].get<bool>()) std::printf("  (non-finite: the figures mean nothing)");
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

int bench_tearing(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--tearing");
  if (opts.flag("--help")) {
    std::puts(kTearingHelp);
    return 0;
  }
  const std::string device = opts.value("--device", "cpu");
  const auto sizes = parse_phyxel_sizes(
      opts.value("--sizes", device == "cpu" ? "10000,100000" : "10000,100000,1000000"), 1000);
  const double tear_stress = opts.number("--tear-stress", 12000, 1e-3, 1e12);
  const int64_t steps = opts.integer("--steps", 64, 1, 1 << 20);
  const int64_t repeats = opts.integer("--repeats", 5, 1, 1000);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string out_dir = opts.value("--out", "");
  opts.finish();

  std::printf(
      "tearing cost: a probe ploughing through an elastic box at %.1f m/s, "
      "tear_stress %g Pa\n",
      kCrossingSpeed, tear_stress);
  std::printf("%-40s %9s %10s %10s %10s %9s %10s %9s", "device", "phyxels", "intact ms",
              "tearing ms", "tear ms", "share", "steps/s", "torn");
  if (device != "cpu") std::printf(" %9s %9s %9s %9s", "princ us", "tear us", "step us", "tearing");
  std::printf("\n");
  nlohmann::json rows = nlohmann::json::array();
  for (const int64_t size : sizes) {
    rows.push_back(tearing_row(device, threads, size, tear_stress, steps, repeats));
    print_row(rows.back());
  }
  std::printf(
      "(ms per step: wall time, median of %lld repeats of %lld steps, the box without and with "
      "tear_stress; tear ms: the difference; torn: pairs per step; princ us, tear us: the GPU's "
      "principal-stress and tear passes per step, timestamps; step us, tearing: all the GPU's "
      "passes of a step without and with tear_stress)\n",
      static_cast<long long>(repeats), static_cast<long long>(steps));
  if (!out_dir.empty())
    write_json_file(std::filesystem::path(out_dir) / "tearing.json", {{"tearing", rows}});
  return 0;
}

}  // namespace phyxel::bench
