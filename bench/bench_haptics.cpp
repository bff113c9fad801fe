// phyxel bench --haptics: the 1 kHz haptic loop's timing while the solver runs in real time (a
// scene's first tool switched to "control": "haptic", the scripted device replaying its path),
// the same loop with no solver (idle baseline), and what tool contact costs per step on boxes
// of several sizes with a probe pressed into them (CPU wall time; GPU pass timestamps and
// wall time). Writes a table on stdout and, with --out DIR, DIR/haptics.csv and
// DIR/haptics.json.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "app/run_report.h"
#include "bench/bench_tools.h"
#include "bench/benches.h"
#include "bench/timing.h"
#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "engine/surgery/haptic_session.h"

namespace phyxel::bench {
namespace {

constexpr const char* kHapticsHelp =
    "usage: phyxel bench --haptics [options]\n"
    "\n"
    "1. The haptic loop (1 kHz, docs/haptics.md) while the solver runs paced to the wall\n"
    "   clock: the scene's first tool is driven through the loop (\"control\": \"haptic\"),\n"
    "   its device replaying the tool's path from where it reaches the tissue, repeated, on\n"
    "   the simulation's clock (so that a solver slower than real time still sees the\n"
    "   authored speed); and the loop alone, its path on the wall clock (idle baseline).\n"
    "   Per run: ticks, tick period mean / p99 / max, overruns (> 2 ms), the largest force\n"
    "   jump between ticks and the largest force on the hand, the physics' real-time factor\n"
    "   and steps per second, the most phyxels in contact.\n"
    "2. Contact cost: an elastic box per size with a probe (capsule, radius 4 mm) pressed 4 mm\n"
    "   into its top; seconds per step with and without the tool (median of the repeats),\n"
    "   the contact share of the step, broad-phase candidates and phyxels in contact; GPU rows\n"
    "   add the per-pass timestamps (GpuSolver::profile).\n"
    "\n"
    "options:\n"
    "  --device D        cpu (default), gpu, gpu:N or part of a GPU's name\n"
    "  --scene FILE      scene of part 1 (default scenes/probe_indent.json); needs a tool\n"
    "  --refine K        divides the scene's spacing and support radius by K, a number from 1\n"
    "                    to 16 (phyxels x K^3; 2.78 makes the probe scene's brain 100k)\n"
    "  --seconds S       wall seconds of each part-1 run (default 10)\n"
    "  --sizes LIST      part 2 box sizes in phyxels (default 10000,100000 on the CPU,\n"
    "                    10000,100000,1000000 on a GPU)\n"
    "  --steps N         part 2 steps per timed repeat (default: about 0.3 s of work)\n"
    "  --repeats N       part 2 timed repeats, the median is reported (default 5)\n"
    "  --threads N       CPU solver threads (default: all cores)\n"
    "  --no-loop         skip part 1\n"
    "  --no-contact      skip part 2\n"
    "  --out DIR         write DIR/haptics.csv and DIR/haptics.json";

// The CSV's columns: every row of either part, empty where a column does not apply.
constexpr const char* kHeader =
    "part,scene,device,phyxels,refine,seconds,ticks,period_mean_ms,period_p99_ms,"
    "period_max_ms,overruns,max_force_jump_n,max_hand_force_n,snapshots,"
    "real_time_factor,physics_steps_per_s,max_contacts,steps,step_ms_no_tool,"
    "step_ms_tool,contact_share_percent,candidates,contacts,gpu_step_us_no_tool,"
    "gpu_step_us_tool,gpu_contact_us,gpu_contact_share_percent,finite";

std::vector<std::string> columns() {
  std::vector<std::string> out;
  std::stringstream ss(kHeader);
  for (std::string c; std::getline(ss, c, ',');) out.push_back(c);
  return out;
}

// The part-1 scene: refined, its first tool (the others dropped) haptic.
Scene haptic_scene(const std::string& file, double refine) {
  Scene scene = load_scene(file);
  if (scene.tools.empty())
    throw UsageError("phyxel bench --haptics: --scene " + file +
                     ": the scene has no tool to drive through the haptic loop");
  refine_scene(scene, refine);
  scene.tools.resize(1);
  scene.tools[0].control = ToolDesc::Control::Haptic;
  scene.simulation.until_rest.enabled = false;
  return scene;
}

// The scripted device's path: the tool's path from its first key that reaches the tissue's
// bounds (the approach through the air is dropped), repeated with a 50 ms rest between
// repeats to cover `seconds` and a margin.
std::vector<ToolKey> bench_path(const ToolDesc& tool, const PhyxelSet& set, double seconds) {
  Bounds tissue;
  for (const Vec3& x : set.rest) tissue.extend({x, x});
  auto reaches = [&](const ToolKey& k) {
    const Bounds b = tool_bounds(tool.shape, {k.position, k.axis});
    return (b.min.array() <= tissue.max.array()).all() &&
           (b.max.array() >= tissue.min.array()).all();
  };
  size_t first = 0;
  while (first < tool.path.size() && !reaches(tool.path[first])) ++first;
  if (first == tool.path.size()) first = 0;
  const std::vector<ToolKey> once(tool.path.begin() + long(first), tool.path.end());
  const double t0 = once.front().t, period = once.back().t - t0 + 0.05;
  std::vector<ToolKey> path;
  for (int c = 0; c * period < seconds + 5; ++c)
    for (const ToolKey& k : once) {
      ToolKey key = k;
      key.t = k.t - t0 + c * period;
      path.push_back(key);
    }
  return path;
}

// The scripted device of the runs with a solver: the path replayed on the simulation's clock
// (the end time of the newest step) instead of the wall clock, so that the tool moves through
// the tissue at its authored speed also where the solver is slower than real time (a
// ScriptedDevice would sweep the tool through the tissue as many times faster as the solver
// is slower). At or above real time the two are the same up to one step.
class SimClockDevice : public HapticDevice {
 public:
  SimClockDevice(std::vector<ToolKey> path, const std::atomic<double>& sim_time)
      : path_(std::move(path)), sim_time_(sim_time) {}
  std::string name() const override { return "scripted (simulated time)"; }
  HapticSample read(double) override {
    HapticSample sample;
    sample.pose = pose_at(path_, sim_time_.load(std::memory_order_relaxed));
    sample.pose.axis.normalize();
    sample.valid = true;
    return sample;
  }
  void send(const Vec3&, double, uint32_t) override {}

 private:
  std::vector<ToolKey> path_;
  const std::atomic<double>& sim_time_;
};

nlohmann::json loop_row(const std::string& part, const std::string& scene, size_t phyxels,
                        double refine, double seconds, const HapticStats& s) {
  return {{"part", part},
          {"scene", scene},
          {"phyxels", phyxels},
          {"refine", refine},
          {"seconds", seconds},
          {"ticks", s.ticks},
          {"period_mean_ms", s.period_mean_ms},
          {"period_p99_ms", s.period_p99_ms},
          {"period_max_ms", s.period_max_ms},
          {"overruns", s.overruns},
          {"max_force_jump_n", s.max_force_jump},
          {"max_hand_force_n", s.max_hand_force},
          {"snapshots", s.snapshots},
          {"realtime_priority", s.realtime_priority}};
}

// The loop alone: the scene's haptic tool on its scripted device, nothing published.
nlohmann::json idle_loop(Scene scene, const PhyxelSet& set, const std::string& file, double refine,
                         double seconds) {
  scene.tools[0].path = bench_path(scene.tools[0], set, seconds);
  HapticSession haptics(scene, "scripted");
  const auto t0 = std::chrono::steady_clock::now();
  haptics.start();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  haptics.stop();
  nlohmann::json row = loop_row("loop_idle", file, 0, refine, seconds_since(t0),
                                haptics.loops().front().loop->stats());
  row["device"] = "none";
  return row;
}

// The loop while `device` simulates the scene paced to the wall clock, for `seconds`.
nlohmann::json solver_loop(Scene scene, const PhyxelSet& set, const std::string& file,
                           double refine, const std::string& device, int threads, double seconds) {
  auto solver = make_bench_solver(device, set, scene.simulation.gravity, threads);
  std::printf("(%s refine %g: %zu phyxels on %s)\n", file.c_str(), refine, set.size(),
              solver->device().c_str());
  std::fflush(stdout);
  std::atomic<double> sim_time{0};
  scene.tools[0].path = bench_path(scene.tools[0], set, seconds);  // also the loop's start
  const std::vector<ToolKey> path = scene.tools[0].path;
  HapticSession haptics(scene,
                        [&](size_t) { return std::make_shared<SimClockDevice>(path, sim_time); });
  RunOptions options;
  options.steps = int64_t(1) << 40;
  options.real_time = true;
  options.tool_pose = haptics.pose_source();
  uint32_t max_contacts = 0;
  options.on_tool_step = [&](int64_t, double t, const std::vector<ToolStepRecord>& records) {
    haptics.publish(t, records);
    sim_time.store(t, std::memory_order_relaxed);
    for (const ToolStepRecord& r : records) max_contacts = std::max(max_contacts, r.contacts);
  };
  const auto t0 = std::chrono::steady_clock::now();
  options.stop_requested = [&] { return seconds_since(t0) >= seconds; };
  haptics.start();
  const RunResult result = run_simulation(scene, set, *solver, options);
  haptics.stop();
  nlohmann::json row = loop_row("loop_solver", file, set.size(), refine, result.wall_seconds,
                                haptics.loops().front().loop->stats());
  row["device"] = solver->device();
  row["real_time_factor"] = result.real_time_factor;
  row["physics_steps_per_s"] = double(result.steps_done) / std::max(result.wall_seconds, 1e-9);
  row["steps"] = result.steps_done;
  row["max_contacts"] = max_contacts;
  row["finite"] = !result.non_finite && !result.unstable;
  row["wall_split_s"] = app::wall_split_json(result.split);
  return row;
}

// The part-2 scene: bench_scene's box (0.1 m, clamped at its base) and, with_tool, a vertical
// capsule probe (radius 4 mm, like scenes/probe_indent.json's) whose lowest point is 4 mm
// below the top face at its centre: the tip's hemisphere touches a few to a few hundred
// phyxels depending on the spacing. It starts with its tip on the top face and presses in at
// kProbeSpeed (a surgeon's pace) during the warm-up, then holds still. (A probe that starts
// embedded projects the phyxels inside it out in one substep: at 1M phyxels that is a few
// hundred m/s, and the box runs away.)
constexpr double kProbeRadius = 0.004, kProbeDepth = 0.004, kProbeSpeed = 0.2;

Scene contact_scene(int64_t size, bool with_tool) {
  Scene scene = bench_scene(size);
  if (!with_tool) return scene;
  ToolDesc probe;
  probe.name = "probe";
  probe.shape.type = ToolShape::Type::Capsule;
  probe.shape.radius = kProbeRadius;
  probe.shape.length = 0.04;
  ToolKey top, down;
  top.position = Vec3(0.05, 0.05, 0.1 + kProbeRadius);
  top.axis = Vec3::UnitZ();
  down = top;
  down.t = kProbeDepth / kProbeSpeed;
  down.position.z() -= kProbeDepth;
  probe.path = {top, down};
  probe.friction = 0.2;
  scene.tools.push_back(probe);
  return scene;
}

// GPU time of one step: the per-step passes (kick_drift runs once per submit); with the contact
// in the force pass (GpuSolverOptions::contact_in_force), force+contact for most substeps.
double gpu_step_ns(const std::vector<gpu::PassTime>& passes) {
  const double fused = pass_ns(passes, "force+contact");
  return pass_ns(passes, "stress") +
         (fused > 0 ? fused : pass_ns(passes, "force") + pass_ns(passes, "contact"));
}

// Both boxes are built first and their repeats interleaved, so that a busy machine slows
// both alike.
nlohmann::json contact_row(const std::string& device, int threads, int64_t size,
                           int64_t fixed_steps, int64_t repeats) {
  ToolBenchCase plain(device, threads, contact_scene(size, false)),
      tool(device, threads, contact_scene(size, true));
  // Warm-up: first submits, and the probe presses in (the plain box takes as many steps).
  const int64_t press = static_cast<int64_t>(std::ceil(kProbeDepth / kProbeSpeed / tool.dt));
  plain.run(press);
  tool.run(press);
  const double ten = time_repeats([&] { tool.run(10); }, 1).median;
  const int64_t steps =
      fixed_steps > 0
          ? fixed_steps
          : std::clamp<int64_t>(static_cast<int64_t>(0.3 / std::max(ten / 10, 1e-9)), 3, 100000);
  const auto [s_plain, s_tool] = interleaved_step_seconds(plain, tool, steps, repeats);
  nlohmann::json row = {
      {"part", "contact"},
      {"device", tool.solver->device()},
      {"phyxels", tool.set.size()},
      {"steps", steps},
      {"repeats", repeats},
      {"step_ms_no_tool", s_plain * 1e3},
      {"step_ms_tool", s_tool * 1e3},
      {"contact_share_percent", 100 * (s_tool - s_plain) / std::max(s_tool, 1e-30)},
      {"candidates",
       need(tool.solver->tools(), *tool.solver, "simulate tools").contact_candidates()},
      {"contacts", tool.track.stats().front().contacts},
      {"max_contacts", tool.track.stats().front().max_contacts},
      {"finite", plain.solver->first_non_finite() < 0 && tool.solver->first_non_finite() < 0}};
  const std::vector<gpu::PassTime> passes_plain = plain.profile(32), passes = tool.profile(32);
  if (!passes.empty()) {
    const double with = gpu_step_ns(passes), without = gpu_step_ns(passes_plain);
    // The contact's own pass, or what it adds to the force pass.
    const double fused = pass_ns(passes, "force+contact");
    const double contact =
        fused > 0 ? fused - pass_ns(passes_plain, "force") : pass_ns(passes, "contact");
    row["gpu_step_us_no_tool"] = without * 1e-3;
    row["gpu_step_us_tool"] = with * 1e-3;
    row["gpu_contact_us"] = contact * 1e-3;
    row["gpu_contact_share_percent"] = 100 * contact / std::max(with, 1e-30);
    nlohmann::json by_name = nlohmann::json::object();
    for (const gpu::PassTime& p : passes) by_name[p.name] = p.ns;
    row["gpu_pass_ns_tool"] = by_name;
  }
  return row;
}

std::string csv_cell(const nlohmann::json& row, const std::string& column) {
  if (!row.contains(column)) return "";
  const nlohmann::json& v = row[column];
  if (v.is_string()) {
    std::string s = v.get<std::string>();
    std::replace(s.begin(), s.end(), ',', ';');
    return s;
  }
  return v.dump();
}

void write_outputs(const std::filesystem::path& dir, const nlohmann::json& loop_rows,
                   const nlohmann::json& contact_rows) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw std::runtime_error("phyxel bench --haptics: --out " + dir.string() +
                             ": cannot create the folder (" + ec.message() + ")");
  std::ofstream csv(dir / "haptics.csv");
  const std::vector<std::string> cols = columns();
  csv << kHeader << "\n";
  for (const nlohmann::json* rows : {&loop_rows, &contact_rows})
    for (const nlohmann::json& row : *rows) {
      for (size_t c = 0; c < cols.size(); ++c) csv << (c ? "," : "") << csv_cell(row, cols[c]);
      csv << "\n";
    }
  std::ofstream json(dir / "haptics.json");
  json << nlohmann::json{{"haptic_loop", loop_rows}, {"contact", contact_rows}}.dump(2) << "\n";
  if (!csv || !json) throw std::runtime_error("cannot write " + (dir / "haptics.*").string());
}

void print_loop_row(const nlohmann::json& r) {
  const bool solver = r["part"] == "loop_solver";
  std::printf("%-40.40s %8lld %7llu %8.3f %8.3f %8.3f %8llu %9.3f %9.3f",
              r["device"].get<std::string>().c_str(), r["phyxels"].get<long long>(),
              r["ticks"].get<unsigned long long>(), r["period_mean_ms"].get<double>(),
              r["period_p99_ms"].get<double>(), r["period_max_ms"].get<double>(),
              r["overruns"].get<unsigned long long>(), r["max_force_jump_n"].get<double>(),
              r["max_hand_force_n"].get<double>());
  if (solver)
    std::printf(" %6.3f %9.1f %8u%s", r["real_time_factor"].get<double>(),
                r["physics_steps_per_s"].get<double>(), r["max_contacts"].get<uint32_t>(),
                r["finite"].get<bool>() ? "" : "  (stopped: unstable or non-finite)");
  if (r.contains("realtime_priority") && !r["realtime_priority"].get<bool>())
    std::printf("  (normal priority: SCHED_FIFO refused)");
  std::printf("\n");
  if (r.contains("wall_split_s")) {
    const nlohmann::json& w = r["wall_split_s"];
    std::printf("  wall s: advance %.3f, checks %.3f, callbacks %.3f, pacing %.3f, outputs %.3f\n",
                w["advance"].get<double>(), w["checks"].get<double>(), w["callbacks"].get<double>(),
                w["pacing"].get<double>(), w["outputs"].get<double>());
  }
  std::fflush(stdout);
}

void print_contact_row(const nlohmann::json& r) {
  std::printf("%-40.40s %9lld %10.4g %10.4g %9.1f%% %10llu %9u",
              r["device"].get<std::string>().c_str(), r["phyxels"].get<long long>(),
              r["step_ms_no_tool"].get<double>(), r["step_ms_tool"].get<double>(),
              r["contact_share_percent"].get<double>(), r["candidates"].get<unsigned long long>(),
              r["max_contacts"].get<uint32_t>());
  if (r.contains("gpu_contact_us"))
    std::printf(" %10.1f %10.1f %9.1f %8.1f%%", r["gpu_step_us_no_tool"].get<double>(),
                r["gpu_step_us_tool"].get<double>(), r["gpu_contact_us"].get<double>(),
                r["gpu_contact_share_percent"].get<double>());
  if (!r["finite"].get<bool>()) std::printf("  (non-finite: the figures mean nothing)");
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

int bench_haptics(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--haptics");
  if (opts.flag("--help")) {
    std::puts(kHapticsHelp);
    return 0;
  }
  const std::string device = opts.value("--device", "cpu");
  const std::string scene_file = opts.value("--scene", "scenes/probe_indent.json");
  const double refine = opts.number("--refine", 1, 1, kMaxRefine);
  const double seconds = opts.number("--seconds", 10, 0.01, 3600);
  const auto sizes = parse_phyxel_sizes(
      opts.value("--sizes", device == "cpu" ? "10000,100000" : "10000,100000,1000000"), 8);
  const int64_t fixed_steps = opts.integer("--steps", 0, 0, 1 << 30);
  const int64_t repeats = opts.integer("--repeats", 5, 1, 1000);
  const int threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const bool loop = !opts.flag("--no-loop");
  const bool contact = !opts.flag("--no-contact");
  const std::string out_dir = opts.value("--out", "");
  opts.finish();

  nlohmann::json loop_rows = nlohmann::json::array(), contact_rows = nlohmann::json::array();
  if (loop) {
    const Scene scene = haptic_scene(scene_file, refine);
    const PhyxelSet set = sample_scene(scene);
    std::printf("haptic loop (1 kHz, overrun > 2 ms), %s, %.3g s per run\n", scene_file.c_str(),
                seconds);
    std::printf("%-40s %8s %7s %8s %8s %8s %8s %9s %9s %6s %9s %8s\n", "solver", "phyxels", "ticks",
                "mean ms", "p99 ms", "max ms", "overruns", "jump N", "hand N", "RTF", "steps/s",
                "contacts");
    loop_rows.push_back(idle_loop(scene, set, scene_file, refine, seconds));
    print_loop_row(loop_rows.back());
    loop_rows.push_back(solver_loop(scene, set, scene_file, refine, device, threads, seconds));
    print_loop_row(loop_rows.back());
    std::printf(
        "(jump N: largest change of the hand force between ticks; hand N: largest force on the "
        "hand; RTF: simulated over wall seconds; contacts: most phyxels under the tool)\n");
  }
  if (contact) {
    std::printf("\ncontact cost: probe r = %.0f mm pressed %.0f mm into an elastic box\n",
                kProbeRadius * 1e3, kProbeDepth * 1e3);
    std::printf("%-40s %9s %10s %10s %10s %10s %9s", "device", "phyxels", "ms/step", "+tool ms",
                "contact", "candidates", "contacts");
    if (device != "cpu")
      std::printf(" %10s %10s %9s %9s", "GPU us", "+tool us", "contact", "share");
    std::printf("\n");
    for (const int64_t size : sizes) {
      contact_rows.push_back(contact_row(device, threads, size, fixed_steps, repeats));
      print_contact_row(contact_rows.back());
    }
    std::printf(
        "(ms/step: wall time per step, median of %lld repeats, without and with the tool; "
        "contact: the difference's share of the step; GPU us: the per-step passes' timestamps)\n",
        static_cast<long long>(repeats));
  }
  if (!out_dir.empty()) write_outputs(out_dir, loop_rows, contact_rows);
  return 0;
}

}  // namespace phyxel::bench
