// phyxel soak SCENE: a long run under surgery (docs/performance.md "Soak"): the run loop of
// `phyxel run`, headless, sampled at every tenth of its steps for resident memory (VmRSS), GPU
// memory, the step rate, the kinetic energy and the topology edits of each tenth (pairs cut,
// pairs torn, phyxels aspirated, grips closed on tissue), and what of the memory the edits
// hold (the severed pairs, kept for good; the heap in use); DIR/soak.json holds
// the samples and a hash of the final u and v, so that two runs and a resumed one can be
// compared bit for bit. Timing is reported, never judged.
#include <malloc.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/options.h"
#include "compute/gpu_solver.h"
#include "engine/run/checkpoint.h"
#include "engine/run/simulation.h"
#include "engine/sampling/phyxel_set.h"

namespace phyxel::app {
namespace {

constexpr const char* kSoakHelp =
    "usage: phyxel soak SCENE [options]\n"
    "\n"
    "Runs SCENE headless (no points files, no frames) and samples the run at every tenth of\n"
    "its steps: resident memory, GPU memory, steps per second, kinetic energy, and the edits\n"
    "of each tenth: pairs cut, pairs torn, phyxels aspirated, grips. Beside the resident\n"
    "memory: the heap in use (malloc's count) and the severed pairs held so far, which the run\n"
    "keeps for good (checkpoints, rest-space maps): memory that grows with the edits. Writes\n"
    "DIR/soak.json (the samples and a hash of the final displacements and velocities) and\n"
    "prints the table.\n"
    "\n"
    "options:\n"
    "  --steps N             steps (default: the scene's simulation.steps)\n"
    "  --device D            cpu (default), gpu, gpu:N or part of a device name\n"
    "  --validate            with a GPU device: Vulkan validation layers on\n"
    "  --threads N           CPU threads (default: all cores)\n"
    "  --out DIR             output folder (default: out)\n"
    "  --checkpoint-every N  DIR/checkpoint.phx every N steps and at the end\n"
    "  --resume DIR          continue the soak checkpointed in DIR (writes into DIR)\n"
    "  --quiet               no table\n"
    "  --help                this text";

// Resident memory of this process, KiB (/proc/self/statm's second field).
long resident_kib() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

// Bytes the process has allocated through malloc and not freed (all arenas, mmap'ed blocks
// too): unlike the resident size, not rounded to pages nor kept up by freed memory.
size_t heap_in_use() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

// FNV-1a 64 over the bytes of u and v: equal hashes, equal states (for the tests' comparisons).
std::string state_hash(const PointState& s) {
  uint64_t h = fnv1a64(s.displacement.data(), s.displacement.size() * sizeof(Vec3));
  h = fnv1a64(s.velocity.data(), s.velocity.size() * sizeof(Vec3), h);
  char text[32];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

// Topology edits so far (a resumed soak counts from its checkpoint's).
struct Edits {
  size_t cut = 0;        // pairs severed by a blade
  size_t torn = 0;       // pairs torn
  size_t aspirated = 0;  // phyxels removed by aspiration
  size_t grips = 0;      // a grasper closing on tissue (its held count rising from 0)
};

struct Sample {
  int64_t step = 0;
  double wall = 0;  // s since the soak's loop began
  long rss_kib = 0;
  size_t heap_bytes = 0;
  size_t severed_held = 0;                        // pairs severed so far (the solver's log)
  uint64_t gpu_allocated = 0, gpu_available = 0;  // bytes (GPU solvers only)
  double kinetic = 0;                             // J
  bool finite = true;
  Edits edits;
};

// The state now: kinetic energy (of the phyxels not aspirated: `removed`), finiteness, memory.
Sample take_sample(Solver& solver, const PhyxelSet& set, const std::vector<uint8_t>& removed,
                   int64_t step, double wall, const Edits& edits) {
  Sample s;
  s.step = step;
  s.wall = wall;
  s.rss_kib = resident_kib();
  s.heap_bytes = heap_in_use();
  if (auto* gpu = dynamic_cast<gpu::GpuSolver*>(&solver)) {
    s.gpu_allocated = gpu->context().allocated_bytes();
    s.gpu_available = gpu->context().available_device_memory();
  }
  const PointState state = solver.read_state(false);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& v = state.velocity[i];
    s.finite = s.finite && v.allFinite() && state.displacement[i].allFinite();
    if (!removed[i]) s.kinetic += 0.5 * set.mass[i] * v.squaredNorm();
  }
  s.edits = edits;
  return s;
}

nlohmann::json report(const std::vector<Sample>& samples, const Edits& start,
                      const RunResult& result, const std::vector<SeveredPair>& severed,
                      const std::string& hash) {
  nlohmann::json tenths = nlohmann::json::array();
  for (size_t k = 0; k < samples.size(); ++k) {
    const Sample& s = samples[k];
    const Sample* before = k > 0 ? &samples[k - 1] : nullptr;
    const Edits& e0 = before ? before->edits : start;
    const double steps = before ? double(s.step - before->step) : double(s.step);
    const double wall = before ? s.wall - before->wall : s.wall;
    tenths.push_back({{"step", s.step},
                      {"wall_s", s.wall},
                      {"steps_per_s", wall > 0 ? steps / wall : 0.0},
                      {"rss_kib", s.rss_kib},
                      {"heap_bytes", s.heap_bytes},
                      {"severed_pairs_held", s.severed_held},
                      {"gpu_allocated_bytes", s.gpu_allocated},
                      {"gpu_available_bytes", s.gpu_available},
                      {"kinetic_energy_j", s.finite ? s.kinetic : -1.0},
                      {"finite", s.finite},
                      {"cut_pairs", s.edits.cut - e0.cut},
                      {"torn_pairs", s.edits.torn - e0.torn},
                      {"aspirated_phyxels", s.edits.aspirated - e0.aspirated},
                      {"grips", s.edits.grips - e0.grips}});
  }
  nlohmann::json j;
  j["tenths"] = tenths;
  j["steps_done"] = result.steps_done;
  j["resumed_from_step"] = result.resumed_from;
  j["substeps"] = result.plan.substeps;
  j["non_finite"] = result.non_finite;
  j["unstable"] = result.unstable;
  j["aspiration_events"] = result.aspiration.events;
  j["severed_pairs"] = severed.size();
  size_t torn = 0;
  for (const SeveredPair& p : severed) torn += p.torn ? 1 : 0;
  j["torn_pairs"] = torn;
  j["state_hash"] = hash;
  nlohmann::json tools = nlohmann::json::array();
  for (const ToolRunStats& t : result.tools)
    tools.push_back({{"name", t.name}, {"max_held", t.max_held}, {"max_force_n", t.max_force}});
  j["tools"] = tools;
  return j;
}

void print_table(const nlohmann::json& j) {
  std::printf("%10s %9s %11s %10s %10s %8s %14s %12s %6s %6s %6s %6s\n", "step", "wall s",
              "steps/s", "RSS KiB", "heap KiB", "severed", "GPU alloc B", "kinetic J", "cut",
              "torn", "aspir", "grips");
  for (const auto& t : j["tenths"])
    std::printf("%10lld %9.2f %11.1f %10ld %10zu %8zu %14llu %12.3e %6zu %6zu %6zu %6zu\n",
                t["step"].get<long long>(), t["wall_s"].get<double>(),
                t["steps_per_s"].get<double>(), t["rss_kib"].get<long>(),
                t["heap_bytes"].get<size_t>() / 1024, t["severed_pairs_held"].get<size_t>(),
                t["gpu_allocated_bytes"].get<unsigned long long>(),
                t["kinetic_energy_j"].get<double>(), t["cut_pairs"].get<size_t>(),
                t["torn_pairs"].get<size_t>(), t["aspirated_phyxels"].get<size_t>(),
                t["grips"].get<size_t>());
  std::printf("state %s, %lld aspirations\n", j["state_hash"].get<std::string>().c_str(),
              j["aspiration_events"].get<long long>());
}

}  // namespace

int soak_command(const Args& args) {
  OptionParser opts("soak", args);
  if (opts.flag("--help")) {
    std::puts(kSoakHelp);
    return 0;
  }
  const std::string device = opts.value("--device", "cpu");
  const std::string resume_dir = opts.value("--resume", "");
  const std::filesystem::path out_dir =
      opts.value("--out", resume_dir.empty() ? "out" : resume_dir);
  const int64_t checkpoint_every = opts.integer("--checkpoint-every", 0, 0, int64_t(1) << 40);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const bool validate = opts.flag("--validate");
  const bool quiet = opts.flag("--quiet");
  const int64_t steps_override = opts.integer("--steps", -1, 1, int64_t(1) << 40);
  const std::vector<std::string> positional = opts.finish();
  if (positional.size() != 1) throw UsageError("phyxel soak: expected one SCENE file");
  const InterruptGuard interrupts;
  std::unique_ptr<Checkpoint> checkpoint;
  if (!resume_dir.empty())
    checkpoint = std::make_unique<Checkpoint>(read_checkpoint(out_dir / kCheckpointFile));
  Scene scene = load_scene(positional[0]);
  scene.output.every = 0;  // the soak writes no points files but the last
  const PhyxelSet set = sample_scene(scene);
  std::filesystem::create_directories(out_dir);
  std::unique_ptr<Solver> solver;
  if (device != "cpu") {
    gpu::ContextOptions context;
    context.device = device;
    context.validation = validate;
    solver = make_gpu_solver(set, scene.simulation.gravity, context);
  } else {
    solver = make_cpu_solver(set, scene.simulation.gravity, threads, false);
  }
  RunOptions options;
  options.steps = steps_override > 0 ? steps_override : scene.simulation.steps;
  options.out_dir = out_dir;
  options.resume = checkpoint.get();
  options.checkpoint_every = checkpoint_every > 0 ? checkpoint_every
                             : checkpoint         ? checkpoint->checkpoint_every
                                                  : 0;
  options.stop_requested = [] { return InterruptGuard::received() != 0; };
  // The aspirated phyxels (they keep the velocity they left with): out of the energy.
  std::vector<uint8_t> removed(set.size(), 0);
  if (checkpoint)
    for (const uint32_t i : checkpoint->aspiration.removed)
      if (i < removed.size()) removed[i] = 1;
  Edits edits;
  std::vector<uint32_t> held(scene.tools.size(), 0);  // per tool, at the last step
  if (checkpoint) {
    edits.aspirated = checkpoint->aspiration.removed.size();
    for (const SeveredPair& p : checkpoint->severed) ++(p.torn ? edits.torn : edits.cut);
    for (size_t t = 0; t < held.size() && t < checkpoint->tool_stats.size(); ++t)
      held[t] = checkpoint->tool_stats[t].held;
  }
  const Edits edits_start = edits;
  options.on_aspiration = [&](const AspirationEvent& e) {
    for (const uint32_t i : e.removed) removed[i] = 1;
    edits.aspirated += e.removed.size();
  };
  options.on_tool_step = [&](int64_t, double, const std::vector<ToolStepRecord>& records) {
    for (size_t t = 0; t < held.size(); ++t) {
      edits.grips += held[t] == 0 && records[t].held > 0 ? 1 : 0;
      held[t] = records[t].held;
    }
  };
  // The pairs severed since the last sample, cut or torn (the solver's log from `logged` on).
  size_t logged = edits.cut + edits.torn;
  const auto count_severed = [&] {
    for (const SeveredPair& p : need(solver->cutting(), *solver, "cut").severed_since(logged))
      ++(p.torn ? edits.torn : edits.cut);
    logged = severed_pair_count(*solver);
  };
  const int64_t first = checkpoint ? checkpoint->step : 0;
  const auto start = std::chrono::steady_clock::now();
  std::vector<Sample> samples;
  // A sample at each tenth of the steps (the first advance past it).
  options.progress = [&](int64_t step, int64_t total) {
    const int64_t next = first + (total - first) * int64_t(samples.size() + 1) / 10;
    if (samples.size() >= 10 || step < next) return;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    count_severed();
    samples.push_back(take_sample(*solver, set, removed, step, wall, edits));
    samples.back().severed_held = logged;
  };
  const RunResult result = run_simulation(scene, set, *solver, options);
  const nlohmann::json j =
      report(samples, edits_start, result, need(solver->cutting(), *solver, "cut").severed_since(0),
             state_hash(solver->read_state(false)));
  std::ofstream(out_dir / "soak.json") << j.dump(2) << "\n";
  if (!quiet) print_table(j);
  if (const int signal = InterruptGuard::received(); signal != 0)
    return interrupted_exit_status(signal);
  return result.non_finite || result.unstable ? 3 : 0;
}

}  // namespace phyxel::app
