// phyxel bench (no benchmark option): solver speed on elastic boxes of several sizes.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bench/benches.h"
#include "bench/gpu_solver_bench.h"
#include "bench/timing.h"
#include "compute/timing.h"
#include "engine/run/simulation.h"
#include "engine/sampling/phyxel_order.h"

namespace phyxel::bench {
namespace {

constexpr const char* kBenchHelp =
    "usage: phyxel bench [options]\n"
    "\n"
    "Times the solver on an elastic box clamped at its base under gravity, for each size and\n"
    "thread count: median seconds per step over repeats and phyxel-steps per second. GPU rows\n"
    "add GPU memory per phyxel, the counted bytes per phyxel-step against the device's\n"
    "streaming bandwidth (a copy kernel: the roofline), per-pass timestamps, and the error\n"
    "against the CPU reference (double) after the same steps.\n"
    "\n"
    "options:\n"
    "  --device D            cpu (default), gpu, gpu:N, part of a GPU's name, or all (cpu and\n"
    "                        gpu)\n"
    "  --sizes LIST          approximate phyxel counts (default 1000,10000,100000 on the CPU,\n"
    "                        10000,100000,1000000 with a GPU)\n"
    "  --threads LIST        CPU thread counts (default 1,2)\n"
    "  --no-check            no GPU-vs-CPU comparison (sizes whose CPU reference would not\n"
    "                        fit the host's memory); the error column then reads nan\n"
    "  --check-steps N       steps of the GPU-vs-CPU comparison (default 100; 20 above 200k\n"
    "                        phyxels)\n"
    "  --pair-weights W      GPU pair weights: auto (default: recomputed from x0 unless a pair\n"
    "                        was cut), stored (always read), or both\n"
    "  --lanes LIST          GPU invocations per phyxel in the gathering passes: auto (default:\n"
    "                        per pass and size, 1 on a CPU device), 1, 2, 4, 8 or 16; a list\n"
    "                        times each; the lanes column reads stress/force\n"
    "  --order LIST          GPU phyxel numbering: lattice (default: x fastest, as scenes are\n"
    "                        sampled) or morton (Z-order of the lattice coordinates, applied\n"
    "                        once before the solver is built); a list times each\n"
    "  --steps N             steps per timed repeat (default: about 0.5 s of work)\n"
    "  --repeats N           timed repeats, the median is reported (default 5)\n"
    "  --json FILE           also write the rows as JSON\n"
    "\n"
    "other benchmarks:\n"
    "  --accuracy            run time against error on scenes/validation (--accuracy --help)\n"
    "  --skips               what pass selection saves: fixed-only regions and sleeping objects\n"
    "                        (--device D, --scenes LIST, --refine K, --steps N, --threads N,\n"
    "                        --json FILE; --refine divides the spacing by K)\n"
    "  --stability           long soaks in double and float: energy drift, largest speed, first\n"
    "                        non-finite value (--device D, --steps N, default 100000;\n"
    "                        --json FILE)\n"
    "  --render              splat rendering time per frame, and the GPU solver's step rate\n"
    "                        alone and with a frame every 1/60 s (--device D, --surfels LIST,\n"
    "                        --width W, --height H per eye, --mono, --frames N, --no-solver,\n"
    "                        --json FILE); a last row with a video texture and the environment\n"
    "                        on and --video's encode rate at the frame size (--no-video-texture\n"
    "                        skips both; --video-preset P: x264's preset, default veryfast);\n"
    "                        with --scene FILE: that scene's frames at rest with and without\n"
    "                        its render.backdrop (start-up, frame time still and orbiting)\n"
    "  --haptics             the 1 kHz haptic loop's tick timing while the solver runs in real\n"
    "                        time (and idle), and the cost of tool contact per step (--device\n"
    "                        D, --scene FILE, --refine K, --seconds S, --sizes LIST, --out DIR;\n"
    "                        --haptics --help)\n"
    "  --cutting             what a cut update costs per step and the step rate while cutting:\n"
    "                        a scalpel crossing boxes of several sizes (--device D, --sizes\n"
    "                        LIST, --steps N, --repeats N, --out DIR; --cutting --help)\n"
    "  --tearing             what tearing costs per step and the step rate while tearing: a\n"
    "                        probe ploughing through boxes with tear_stress (--device D,\n"
    "                        --sizes LIST, --tear-stress T, --steps N, --repeats N, --out DIR;\n"
    "                        --tearing --help)\n"
    "  --sampling            reading and sampling an image shape: a synthetic two-label volume\n"
    "                        (--size N voxels a side, default 256) to about --phyxels P\n"
    "                        (default 1000000), or --scene FILE's loading and sampling\n"
    "                        (--repeats N, --threads N, --out DIR, --json FILE)\n"
    "  --surgery             the surgery scenes refined K times: substeps/s, real-time factor\n"
    "                        with and without stereo frames at 60/s, host time per part, GPU\n"
    "                        time per pass, the step against a bare box's (--device D,\n"
    "                        --scenes LIST, --refine LIST, --steps N, --out DIR; --surgery\n"
    "                        --help)";

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

}  // namespace

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
  box.material = {1e5, 0.3, 1000, 1.0, std::nullopt, 0.05, std::nullopt};
  Shape base;
  base.type = Shape::Type::Box;
  base.min = Vec3(-1, -1, -1);
  base.max = Vec3(1, 1, 0.5 * spacing);
  box.fixed.push_back(base);
  scene.objects.push_back(box);
  scene.simulation.dt = 1;  // replaced by the stable step below
  return scene;
}

namespace {

// The largest resident set of this process so far (getrusage), bytes.
uint64_t host_peak_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return uint64_t(usage.ru_maxrss) * 1024;  // kilobytes on Linux
}

// The items of a comma-separated option value, empty ones included (the callers refuse them).
std::vector<std::string> comma_items(const std::string& text) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    out.push_back(text.substr(start, comma - start));
    start = comma + 1;
  }
  return out;
}

// --lanes: a comma-separated list of auto (0), 1, 2, 4, 8 and 16.
std::vector<uint32_t> parse_lanes(const std::string& text) {
  std::vector<uint32_t> out;
  for (const std::string& item : comma_items(text)) {
    if (item == "auto") {
      out.push_back(0);
    } else if (item == "1" || item == "2" || item == "4" || item == "8" || item == "16") {
      out.push_back(static_cast<uint32_t>(std::stoul(item)));
    } else {
      throw UsageError("phyxel bench: --lanes " + text + ": '" + item +
                       "' is not auto, 1, 2, 4, 8 or 16");
    }
  }
  return out;
}

// --order: a comma-separated list of lattice and morton.
std::vector<std::string> parse_orders(const std::string& text) {
  const std::vector<std::string> out = comma_items(text);
  for (const std::string& item : out)
    if (item != "lattice" && item != "morton")
      throw UsageError("phyxel bench: --order " + text + ": '" + item +
                       "' is not lattice or morton");
  return out;
}

// Prints one GPU row (and its memory line) and returns it as JSON.
nlohmann::json gpu_row(const GpuBenchResult& r, const std::string& order, uint32_t lanes,
                       double speedup, const gpu::CopyBandwidth& bandwidth,
                       const gpu::LaunchFloor& floor) {
  std::string passes;
  nlohmann::json pass_json = nlohmann::json::object();
  for (const gpu::PassTime& p : r.passes) {
    char text[64];
    std::snprintf(text, sizeof text, "%s%s %.1f", passes.empty() ? "" : ", ", p.name.c_str(),
                  p.ns / 1000);
    passes += text;
    pass_json[p.name] = p.ns;
  }
  std::printf("%9zu %7s %10s %5s %8.1f %11.4g %14.4g %9.0f %10.0f %8.1f%% %8.3gx %10.2g %s\n",
              r.phyxels, order.c_str(), r.pair_weights.c_str(), r.lanes.c_str(),
              r.neighbours_per_phyxel, r.median_seconds_per_step, r.phyxel_steps_per_second,
              r.gpu_bytes_per_phyxel, r.bytes_per_phyxel_step, 100 * r.roofline_fraction, speedup,
              r.error_over_extent, passes.c_str());
  std::printf("%9s memory: %s on the device, host peak %s; %zu ill-conditioned moment matrices%s\n",
              "", gpu::format_bytes(uint64_t(r.gpu_bytes_per_phyxel * double(r.phyxels))).c_str(),
              gpu::format_bytes(host_peak_bytes()).c_str(), r.ill_conditioned,
              r.ill_conditioned != 0 ? " (the box has none: this row's physics is wrong)" : "");
  std::fflush(stdout);
  return {{"device", r.device},
          {"backend", "gpu"},
          {"pair_weights", r.pair_weights},
          {"order", order},
          {"lanes", r.lanes},
          {"lanes_option", lanes == 0 ? std::string("auto") : std::to_string(lanes)},
          {"phyxels", r.phyxels},
          {"neighbours_per_phyxel", r.neighbours_per_phyxel},
          {"median_seconds_per_step", r.median_seconds_per_step},
          {"phyxel_steps_per_second", r.phyxel_steps_per_second},
          {"steps_per_repeat", r.steps_per_repeat},
          {"seconds_per_step_of_each_repeat", r.seconds_per_step},
          {"repeats", r.repeats},
          {"gpu_bytes_per_phyxel", r.gpu_bytes_per_phyxel},
          {"bytes_per_phyxel_step", r.bytes_per_phyxel_step},
          {"copy_bandwidth_gb_per_s", r.copy_gb_per_s},
          {"dma_copy_bandwidth_gb_per_s", bandwidth.dma_gb_per_s},
          {"launch_floor_us",
           {{"barrier", floor.barrier_us},
            {"compute_barrier", floor.compute_barrier_us},
            {"no_barrier", floor.no_barrier_us}}},
          {"roofline_phyxel_steps_per_second", r.roofline_phyxel_steps_per_second},
          {"roofline_fraction", r.roofline_fraction},
          {"pass_ns", pass_json},
          {"speedup_vs_cpu", speedup},
          {"check_steps", r.check_steps},
          {"error_over_extent", r.error_over_extent},
          {"error_over_max_displacement", r.error_over_max_displacement},
          {"max_displacement", r.max_displacement},
          {"finite", r.finite},
          {"ill_conditioned_moment_matrices", r.ill_conditioned},
          {"gpu_bytes", r.gpu_bytes_per_phyxel * double(r.phyxels)},
          {"host_peak_bytes", host_peak_bytes()}};
}

// The GPU rows: one Vulkan context for every size, its streaming bandwidth measured once.
void bench_gpu_rows(const std::string& spec, const std::vector<int64_t>& sizes,
                    const std::string& pair_weights, const std::vector<uint32_t>& lanes_list,
                    const std::vector<std::string>& orders, int64_t steps, int64_t repeats,
                    int64_t check_steps, const std::map<int64_t, double>& cpu_rate,
                    nlohmann::json& rows) {
  gpu::ContextOptions context;
  context.device = spec;
  context.validation = false;
  gpu::Context ctx(context);
  const gpu::CopyBandwidth bandwidth = gpu::measure_copy_bandwidth(ctx);
  std::printf(
      "\n%s: streaming bandwidth %.1f GB/s (read + write, a copy kernel over %s; "
      "vkCmdCopyBuffer %.1f GB/s)\n",
      ctx.info().name.c_str(), bandwidth.gb_per_s, gpu::format_bytes(bandwidth.bytes).c_str(),
      bandwidth.dma_gb_per_s);
  const gpu::LaunchFloor floor = gpu::measure_launch_floor(ctx);
  std::printf(
      "launch floor: %.2f us per dependent dispatch of %u invocations (%.2f us with a "
      "compute-only barrier, %.2f us with none; %d dispatches in one command buffer)\n",
      floor.barrier_us, floor.invocations, floor.compute_barrier_us, floor.no_barrier_us,
      floor.dispatches);
  std::printf("%9s %7s %10s %5s %8s %11s %14s %9s %10s %9s %9s %10s %s\n", "phyxels", "order",
              "weights", "lanes", "nbr/phx", "s/step", "phyxel-steps/s", "B/phyxel", "B/phx-step",
              "roofline", "vs cpu", "err/extent", "passes (us)");
  for (const int64_t size : sizes) {
    // A size the device cannot hold is refused before the box is sampled on the host (the
    // bench box's lattice has 26 neighbours within its support of two spacings).
    try {
      gpu::GpuSolver::check_capacity(ctx, uint64_t(size), uint64_t(size) * 26);
    } catch (const std::exception& e) {
      std::printf("%9lld refused: %s\n", static_cast<long long>(size), e.what());
      rows.push_back({{"device", ctx.info().name},
                      {"backend", "gpu"},
                      {"phyxels", size},
                      {"refused", e.what()}});
      continue;
    }
    Scene scene = bench_scene(size);
    const PhyxelSet lattice_set = sample_scene(scene);
    const double dt = plan_time_step(scene, lattice_set).dt_stable;
    for (const std::string& order : orders) {
      PhyxelSet morton_set;
      if (order == "morton") {
        morton_set = lattice_set;
        permute_phyxels(morton_set, morton_order(morton_set));
      }
      const PhyxelSet& set = order == "morton" ? morton_set : lattice_set;
      for (const bool stored : {false, true}) {
        if (pair_weights != "both" && stored != (pair_weights == "stored")) continue;
        for (const uint32_t lanes : lanes_list) {
          GpuBenchOptions options;
          options.lanes = lanes;
          options.steps = steps;
          options.repeats = repeats;
          options.check_steps = check_steps;
          options.pair_weights = stored ? gpu::GpuSolverOptions::PairWeights::Stored
                                        : gpu::GpuSolverOptions::PairWeights::Auto;
          const GpuBenchResult r =
              bench_gpu_solver(ctx, set, scene.simulation.gravity, dt, bandwidth.gb_per_s, options);
          const auto cpu = cpu_rate.find(size);
          const double speedup =
              cpu != cpu_rate.end() ? r.phyxel_steps_per_second / cpu->second : 0;
          rows.push_back(gpu_row(r, order, lanes, speedup, bandwidth, floor));
        }
      }
    }
  }
  std::printf(
      "(err/extent: max |u_gpu - u_cpu| / box side after the check steps, CPU in double; "
      "'vs cpu': against the fastest CPU row of that size)\n");
}

}  // namespace

int bench_scale(const Args& args) {
  OptionParser opts("bench", args);
  if (opts.flag("--help")) {
    std::puts(kBenchHelp);
    return 0;
  }
  const std::string device = opts.value("--device", "cpu");
  const bool want_cpu = device == "cpu" || device == "all";
  const bool want_gpu = device != "cpu";
  const auto sizes = parse_list(
      opts.value("--sizes", want_gpu ? "10000,100000,1000000" : "1000,10000,100000"), "--sizes");
  const auto threads = parse_list(opts.value("--threads", "1,2"), "--threads");
  const int64_t fixed_steps = opts.integer("--steps", 0, 0, 1 << 30);
  const int64_t repeats = opts.integer("--repeats", 5, 1, 1000);
  const std::string json_file = opts.value("--json", "");
  int64_t check_steps = opts.integer("--check-steps", 0, 0, 1 << 30);
  if (opts.flag("--no-check")) check_steps = -1;
  const std::string pair_weights = opts.value("--pair-weights", "auto");
  const std::vector<uint32_t> lanes = parse_lanes(opts.value("--lanes", "auto"));
  const std::vector<std::string> orders = parse_orders(opts.value("--order", "lattice"));
  opts.finish();
  if (pair_weights != "auto" && pair_weights != "stored" && pair_weights != "both")
    throw UsageError("phyxel bench: --pair-weights " + pair_weights +
                     ": allowed auto, stored or both");

  nlohmann::json rows = nlohmann::json::array();
  std::map<int64_t, double> cpu_rate;  // best CPU phyxel-steps/s per size, for the GPU speedup
  if (want_cpu)
    std::printf("%-26s %9s %8s %12s %16s %10s\n", "device", "phyxels", "nbr/phx", "s/step",
                "phyxel-steps/s", "steps");
  for (const int64_t size : want_cpu ? sizes : std::vector<int64_t>{}) {
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
        const double one = seconds_since(t0);
        steps = std::clamp<int64_t>(static_cast<int64_t>(0.5 / std::max(one, 1e-9)), 3, 100000);
      }
      const double med =
          time_repeats([&] { solver->advance(steps, scene.simulation.dt); }, repeats).median /
          double(steps);
      const double rate = double(set.size()) / med;
      cpu_rate[size] = std::max(cpu_rate[size], rate);
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
  if (want_gpu)
    bench_gpu_rows(device == "all" ? "gpu" : device, sizes, pair_weights, lanes, orders,
                   fixed_steps, repeats, check_steps, cpu_rate, rows);
  write_json_file(json_file, rows);
  return 0;
}

}  // namespace phyxel::bench
