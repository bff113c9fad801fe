// phyxel bench --cutting: what a cut update costs per step (severing, the precompute of the
// touched phyxels) and the step rate while cutting, on boxes of several sizes that a scalpel
// crosses (docs/cutting.md). Each size runs twice, interleaved: the same blade body as a probe
// (contact only) and as a scalpel (contact and cutting); the wall-time difference is the cut's
// cost, and on a GPU the per-pass timestamps give the cut pass alone. Writes a table on stdout
// and, with --out DIR, DIR/cutting.json.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench/bench_tools.h"
#include "bench/benches.h"
#include "bench/timing.h"

namespace phyxel::bench {
namespace {

constexpr const char* kCuttingHelp =
    "usage: phyxel bench --cutting [options]\n"
    "\n"
    "An elastic box per size (0.1 m, clamped at its base) that a scalpel crosses at 0.5 m/s,\n"
    "its vertical blade 7 cm deep (threshold 0: it cuts wherever it moves through tissue).\n"
    "Per size: seconds per step with the blade's body as a probe and as a scalpel (median of\n"
    "the repeats, interleaved), the cut's share of the step, the step rate while cutting, pairs\n"
    "severed per step; GPU rows add the cut pass's own time per step (timestamps).\n"
    "\n"
    "options:\n"
    "  --device D        cpu (default), gpu, gpu:N or part of a GPU's name\n"
    "  --sizes LIST      box sizes in phyxels (default 10000,100000 on the CPU,\n"
    "                    10000,100000,1000000 on a GPU)\n"
    "  --steps N         steps per timed repeat (default 64)\n"
    "  --repeats N       timed repeats, the median is reported (default 5)\n"
    "  --threads N       CPU solver threads (default: all cores)\n"
    "  --out DIR         write DIR/cutting.json";

nlohmann::json cutting_row(const std::string& device, int threads, int64_t size, int64_t steps,
                           int64_t repeats) {
  ToolBenchCase probe(device, threads, crossing_blade_scene(size, false)),
      scalpel(device, threads, crossing_blade_scene(size, true));
  // Warm-up: the blade enters the box.
  const int64_t enter = crossing_entry_steps(scalpel.dt);
  probe.run(enter);
  scalpel.run(enter);
  Cutting& cut = need(scalpel.solver->cutting(), *scalpel.solver, "cut");
  const size_t severed_before = cut.severed_pairs();
  const auto [s_probe, s_scalpel] = interleaved_step_seconds(probe, scalpel, steps, repeats);
  const double severed_per_step =
      double(cut.severed_pairs() - severed_before) / double(steps * repeats);
  nlohmann::json row = {
      {"device", scalpel.solver->device()},
      {"phyxels", scalpel.set.size()},
      {"dt", scalpel.dt},
      {"steps", steps},
      {"repeats", repeats},
      {"step_ms_probe", s_probe * 1e3},
      {"step_ms_scalpel", s_scalpel * 1e3},
      {"cut_ms_per_step", (s_scalpel - s_probe) * 1e3},
      {"cut_share_percent", 100 * (s_scalpel - s_probe) / std::max(s_scalpel, 1e-30)},
      {"steps_per_s_cutting", 1 / std::max(s_scalpel, 1e-30)},
      {"severed_per_step", severed_per_step},
      {"severed_total", cut.severed_pairs()},
      {"candidates",
       need(scalpel.solver->tools(), *scalpel.solver, "simulate tools").contact_candidates()},
      {"finite", probe.solver->first_non_finite() < 0 && scalpel.solver->first_non_finite() < 0}};
  const std::vector<gpu::PassTime> passes = scalpel.profile(32);
  if (!passes.empty()) {
    row["gpu_cut_us"] = pass_ns(passes, "cut") * 1e-3;
    // With the contact in the force pass, force+contact for most substeps.
    const double fused = pass_ns(passes, "force+contact");
    row["gpu_step_us"] =
        (pass_ns(passes, "stress") + pass_ns(passes, "cut") +
         (fused > 0 ? fused : pass_ns(passes, "force") + pass_ns(passes, "contact"))) *
        1e-3;
  }
  return row;
}

void print_row(const nlohmann::json& r) {
  std::printf("%-40.40s %9lld %10.4g %10.4g %10.4g %8.1f%% %10.0f %9.1f",
              r["device"].get<std::string>().c_str(), r["phyxels"].get<long long>(),
              r["step_ms_probe"].get<double>(), r["step_ms_scalpel"].get<double>(),
              r["cut_ms_per_step"].get<double>(), r["cut_share_percent"].get<double>(),
              r["steps_per_s_cutting"].get<double>(), r["severed_per_step"].get<double>());
  if (r.contains("gpu_cut_us"))
    std::printf(" %9.1f %9.1f", r["gpu_cut_us"].get<double>(), r["gpu_step_us"].get<double>());
  if (!r["finite"].get<bool>()) std::printf("  (non-finite: the figures mean nothing)");
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

int bench_cutting(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--cutting");
  if (opts.flag("--help")) {
    std::puts(kCuttingHelp);
    return 0;
  }
  const std::string device = opts.value("--device", "cpu");
  const auto sizes = parse_phyxel_sizes(
      opts.value("--sizes", device == "cpu" ? "10000,100000" : "10000,100000,1000000"), 1000);
  const int64_t steps = opts.integer("--steps", 64, 1, 1 << 20);
  const int64_t repeats = opts.integer("--repeats", 5, 1, 1000);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string out_dir = opts.value("--out", "");
  opts.finish();

  std::printf("cutting cost: a scalpel crossing an elastic box at %.1f m/s, blade 7 cm deep\n",
              kCrossingSpeed);
  std::printf("%-40s %9s %10s %10s %10s %9s %10s %9s", "device", "phyxels", "probe ms",
              "scalpel ms", "cut ms", "share", "steps/s", "severed");
  if (device != "cpu") std::printf(" %9s %9s", "cut us", "step us");
  std::printf("\n");
  nlohmann::json rows = nlohmann::json::array();
  for (const int64_t size : sizes) {
    rows.push_back(cutting_row(device, threads, size, steps, repeats));
    print_row(rows.back());
  }
  std::printf(
      "(ms per step: wall time, median of %lld repeats of %lld steps, blade body as a probe and "
      "as a scalpel; cut ms: the difference; severed: pairs per step; cut us: the GPU's cut "
      "pass per step, timestamps)\n",
      static_cast<long long>(repeats), static_cast<long long>(steps));
  if (!out_dir.empty())
    write_json_file(std::filesystem::path(out_dir) / "cutting.json", {{"cutting", rows}});
  return 0;
}

}  // namespace phyxel::bench
