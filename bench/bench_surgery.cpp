// phyxel bench --surgery: the surgery scenes at several resolutions (`--refine K`, issue #29):
// per scene and K the phyxels, substeps per second and real-time factor of the whole run with
// and without stereo frames drawn at 60 frames per simulated second, the host's time per part
// of the run loop, the GPU's time per pass, and the surgery's substep against the bare elastic
// step of a box of the same phyxel count. Writes a table on stdout and, with --out DIR,
// DIR/surgery.json.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/run_report.h"
#include "bench/bench_tools.h"
#include "bench/benches.h"
#include "bench/timing.h"
#include "compute/gpu_solver.h"
#include "compute/timing.h"
#include "engine/surgery/resection.h"
#include "render/frame_output.h"

namespace phyxel::bench {
namespace {

constexpr const char* kSurgeryHelp =
    "usage: phyxel bench --surgery [options]\n"
    "\n"
    "Runs each surgery scene at each refinement K (every object's spacing and support radius\n"
    "divided by K, as `phyxel run --refine K`) twice on fresh solvers: without frames, and with\n"
    "stereo frames drawn and read back (not written) every 1/60 s of simulated time. Per row:\n"
    "phyxels, substeps per second, real-time factor of both runs, the run loop's host time per\n"
    "part (advance, checks, callbacks, outputs: seconds), the GPU's time per pass over\n"
    "--profile-steps substeps after the run without frames (tools where it left them), the\n"
    "frame writer's host seconds by part (waiting for the frame in flight, cuts, aspirations,\n"
    "video texture, recording and submitting) against the run loop's parts without frames, the\n"
    "GPU's time per pass of the scene's frame drawn alone after the run with frames, the\n"
    "outcome (removed share of each inclusion, aspirated share of each part), the GPU solver's\n"
    "host seconds in its advances (recording, submitting, waiting, the rest; in the run loop's\n"
    "advance, whose remainder is the tools' paths and records), and the surgery's\n"
    "wall time per substep against the bare step of an elastic box of the same phyxel count.\n"
    "\n"
    "options:\n"
    "  --device D          gpu (default), gpu:N, part of a GPU's name, or cpu\n"
    "  --scenes LIST       scene files (default scenes/brain_tumour_removal.json,\n"
    "                      scenes/breast_resection.json)\n"
    "  --refine LIST       refinements K, numbers from 1 to 16 (default 1,2)\n"
    "  --steps N           steps of each run (default: each scene's simulation.steps)\n"
    "  --width W           frame width per eye (default 1920)\n"
    "  --height H          frame height (default 1080)\n"
    "  --fps F             frames per simulated second (default 60)\n"
    "  --no-frames         skip the runs with frames\n"
    "  --profile-steps N   substeps of the GPU pass profile (default 32)\n"
    "  --profile-parts     the profile times the contact, cut and tear passes by their parts\n"
    "  --bare-steps N      steps of each timed repeat of the bare box (default 64; 3 repeats)\n"
    "  --threads N         CPU solver threads (default: all cores)\n"
    "  --out DIR           write DIR/surgery.json";

struct SurgeryOptions {
  std::string device = "gpu";
  int threads = 0;
  int64_t steps = -1;  // -1: the scene's
  int width = 1920, height = 1080;
  double fps = 60;
  bool frames = true;
  int64_t profile_steps = 32;
  bool profile_parts = false;
  int64_t bare_steps = 64;
};

std::vector<double> parse_refinements(const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const double k = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(k) || k < 1 || k > kMaxRefine)
      throw UsageError("phyxel bench: --refine " + text +
                       ": expected a comma-separated list of numbers from 1 to 16");
    out.push_back(k);
  }
  return out;
}

// What a run reports: speed, the host's parts, the outcome.
nlohmann::json run_json(const Scene& scene, const PhyxelSet& set, Solver& solver,
                        const RunResult& r) {
  const double substeps = double(r.steps_done) * double(r.plan.substeps);
  nlohmann::json j = {{"steps", r.steps_done},
                      {"substeps_per_step", r.plan.substeps},
                      {"wall_seconds", r.wall_seconds},
                      {"substeps_per_second", r.wall_seconds > 0 ? substeps / r.wall_seconds : 0.0},
                      {"real_time_factor", r.real_time_factor},
                      {"host_seconds", app::wall_split_json(r.split)},
                      {"finite", !r.non_finite && !r.unstable}};
  nlohmann::json outcome = nlohmann::json::object();
  if (Cutting* cut = solver.cutting(); cut && cut->severed_pairs() > 0)
    for (const InclusionRemoval& c :
         measure_resection(scene, set, solver.neighbours(), cut->pair_alive()).inclusions)
      outcome[c.name] = {{"removed_percent", c.mass > 0 ? 100 * c.removed / c.mass : 0.0},
                         {"whole", c.whole},
                         {"healthy_removed_g", 1e3 * c.healthy_removed}};
  if (r.aspirating)
    for (size_t m = 0; m < r.aspiration.names.size(); ++m)
      outcome[r.aspiration.names[m]]["aspirated_percent"] =
          r.aspiration.initial_mass[m] > 0
              ? 100 * r.aspiration.removed_mass[m] / r.aspiration.initial_mass[m]
              : 0.0;
  j["outcome"] = outcome;
  return j;
}

// The GPU's median time per pass over `substeps` substeps from where the run ended, the tools
// moving on along their paths (empty on the CPU).
nlohmann::json pass_profile(const Scene& scene, Solver& solver, const RunResult& r,
                            int64_t substeps, bool parts) {
  nlohmann::json passes = nlohmann::json::object();
  auto* gpu_solver = dynamic_cast<gpu::GpuSolver*>(&solver);
  if (gpu_solver == nullptr || substeps <= 0) return passes;
  ToolTrack track(scene.tools, nullptr);
  const int64_t first = r.steps_done * r.plan.substeps;
  if (!track.empty()) gpu_solver->set_tool_motion(track.motions(first, substeps, r.plan.dt_used));
  for (const gpu::PassTime& p : gpu_solver->profile(substeps, r.plan.dt_used, parts))
    passes[p.name] = p.ns * 1e-3;
  if (!track.empty()) gpu_solver->tool_samples();
  return passes;
}

// The GPU's time per pass of the scene's frame (the median of 8), drawn alone and waited for
// where the run ended: what a frame costs the GPU whichever queue draws it.
nlohmann::json frame_pass_profile(render::FrameWriter& frames, gpu::GpuSolver& solver) {
  nlohmann::json passes = nlohmann::json::object();
  gpu::Context& ctx = solver.context();
  gpu::PassTimer timer(ctx);
  if (!timer.supported()) return passes;
  gpu::Recorder rec(ctx, "surgery bench frame profile");
  std::map<std::string, std::vector<double>> ns;
  for (int f = 0; f < 8; ++f) {
    timer.reset(rec);
    frames.renderer().record(rec, solver.buffers(), frames.setup(), &timer);
    rec.submit_and_wait();
    for (const gpu::PassTime& p : timer.results()) ns[p.name].push_back(double(p.ns));
  }
  for (auto& [name, v] : ns) passes[name] = median_of(v) * 1e-3;
  return passes;
}

// One run of the scene on a fresh solver; with frames, stereo frames drawn (not written) every
// `frame_every` steps.
nlohmann::json timed_run(const Scene& scene, const PhyxelSet& set, const SurgeryOptions& o,
                         int64_t frame_every) {
  std::unique_ptr<Solver> solver =
      make_bench_solver(o.device, set, scene.simulation.gravity, o.threads);
  RunOptions options;
  options.steps = o.steps >= 0 ? o.steps : scene.simulation.steps;
  std::vector<render::ToolDrawable> tool_poses = render::tool_drawables(scene.tools, 0.0);
  std::unique_ptr<render::FrameWriter> frames;
  auto* gpu_solver = dynamic_cast<gpu::GpuSolver*>(solver.get());
  if (frame_every > 0) {
    render::FrameWriterOptions fo;
    fo.mode = RenderSettings::Mode::Stereo;
    fo.write_files = false;
    fo.validation = false;
    frames = std::make_unique<render::FrameWriter>(scene, set, fo,
                                                   gpu_solver ? &gpu_solver->context() : nullptr);
    std::function<render::RenderInputs()> buffers;
    if (gpu_solver) buffers = [gpu_solver] { return gpu_solver->buffers(); };
    options.frame_every = frame_every;
    options.on_frame = [&frames, &tool_poses, buffers](int64_t step, Solver& s) {
      render::write_solver_frame(*frames, s, step, tool_poses, buffers);
    };
    options.on_aspiration = [&frames](const AspirationEvent& e) { frames->apply_aspiration(e); };
    options.on_tool_step = [&tool_poses](int64_t, double, const std::vector<ToolStepRecord>& rec) {
      for (size_t k = 0; k < rec.size(); ++k) tool_poses[k].pose = rec[k].pose;
    };
    // The frame draws from the solver's buffers only: inside the advance (no drain, no
    // read-back for it).
    options.frames_within_advance = gpu_solver != nullptr;
    options.on_frame_tool_poses = [&tool_poses](const std::vector<ToolPose>& poses) {
      for (size_t k = 0; k < poses.size(); ++k) tool_poses[k].pose = poses[k];
    };
  }
  const RunResult r = run_simulation(scene, set, *solver, options);
  if (frames) frames->finish();
  nlohmann::json j = run_json(scene, set, *solver, r);
  if (gpu_solver) {
    const gpu::GpuSolver::AdvanceHostTimes& t = gpu_solver->advance_host_times();
    j["solver_host_seconds"] = {{"record", t.record},     {"submit", t.submit},
                                {"wait", t.wait},         {"rest", t.rest},
                                {"advances", t.advances}, {"submissions", t.submissions},
                                {"waits", t.waits}};
  }
  if (frame_every > 0) {
    j["frame_every_steps"] = frame_every;
    const render::FrameWriterTimes& t = frames->times();
    j["frame_host_seconds"] = {
        {"frames", t.frames}, {"aspirations", t.aspirations}, {"wait", t.wait},
        {"cuts", t.cuts},     {"aspiration", t.aspiration},   {"video", t.video},
        {"submit", t.submit}};
    if (gpu_solver) j["frame_gpu_pass_us"] = frame_pass_profile(*frames, *gpu_solver);
  } else {
    j["gpu_pass_us"] = pass_profile(scene, *solver, r, o.profile_steps, o.profile_parts);
  }
  frames.reset();  // before the solver: it may own the context
  return j;
}

// The bare elastic step of a box of about `phyxels` phyxels: wall seconds per step, the median
// of three repeats.
double bare_substep_seconds(size_t phyxels, const SurgeryOptions& o) {
  ToolBenchCase bare(o.device, o.threads, bench_scene(int64_t(phyxels)));
  bare.run(8);  // warm-up
  return time_repeats([&] { bare.run(o.bare_steps); }, 3).median / double(o.bare_steps);
}

nlohmann::json surgery_row(const std::string& file, double k, const SurgeryOptions& o) {
  Scene scene = load_scene(file);
  refine_scene(scene, k);
  scene.render.width = o.width;
  scene.render.height = o.height;
  const PhyxelSet set = sample_scene(scene);
  nlohmann::json row = {{"scene", file}, {"refine", k}, {"phyxels", set.size()}};
  row["bare"] = timed_run(scene, set, o, 0);
  if (o.frames) {
    const int64_t every = std::max<int64_t>(1, std::llround(1.0 / (o.fps * scene.simulation.dt)));
    row["frames"] = timed_run(scene, set, o, every);
    row["frames"]["fps_simulated"] = 1.0 / (double(every) * scene.simulation.dt);
  }
  const double substeps = row["bare"]["substeps_per_second"].get<double>();
  const double box = bare_substep_seconds(set.size(), o);
  row["surgery_substep_us"] = substeps > 0 ? 1e6 / substeps : 0.0;
  row["box_substep_us"] = box * 1e6;
  row["surgery_over_box"] = substeps > 0 && box > 0 ? 1 / substeps / box : 0.0;
  return row;
}

// "name us, name us, ..." of a pass profile.
std::string pass_list(const nlohmann::json& passes) {
  std::string out;
  for (const auto& [name, us] : passes.items()) {
    char text[64];
    std::snprintf(text, sizeof text, "%s%s %.1f", out.empty() ? "" : ", ", name.c_str(),
                  us.get<double>());
    out += text;
  }
  return out;
}

// The GPU solver's host seconds in the advances of one run (`run`: a "bare" or "frames" entry).
void print_solver_host(const nlohmann::json& run, const char* which) {
  if (!run.contains("solver_host_seconds")) return;
  const nlohmann::json& t = run["solver_host_seconds"];
  const nlohmann::json& h = run["host_seconds"];
  std::printf(
      "%36s %ssolver's advances: %lld, %lld submissions, %lld waits; host s: record %.3f, "
      "submit %.3f, wait %.3f, rest %.3f, outside the solver %.3f\n",
      "", which, static_cast<long long>(t["advances"].get<int64_t>()),
      static_cast<long long>(t["submissions"].get<int64_t>()),
      static_cast<long long>(t["waits"].get<int64_t>()), t["record"].get<double>(),
      t["submit"].get<double>(), t["wait"].get<double>(), t["rest"].get<double>(),
      h["advance"].get<double>() - t["record"].get<double>() - t["submit"].get<double>() -
          t["wait"].get<double>() - t["rest"].get<double>());
}

void print_row(const nlohmann::json& r) {
  const nlohmann::json& b = r["bare"];
  std::printf("%-28.28s %5g %9zu %10.0f %8.3f", r["scene"].get<std::string>().c_str(),
              r["refine"].get<double>(), r["phyxels"].get<size_t>(),
              b["substeps_per_second"].get<double>(), b["real_time_factor"].get<double>());
  if (r.contains("frames"))
    std::printf(" %8.3f", r["frames"]["real_time_factor"].get<double>());
  else
    std::printf(" %8s", "-");
  const nlohmann::json& h = b["host_seconds"];
  std::printf(" %7.2f %7.2f %7.2f %9.1f %9.1f %6.2fx", h["advance"].get<double>(),
              h["checks"].get<double>(), h["callbacks"].get<double>(),
              r["surgery_substep_us"].get<double>(), r["box_substep_us"].get<double>(),
              r["surgery_over_box"].get<double>());
  std::printf("  %s\n", pass_list(b["gpu_pass_us"]).c_str());
  print_solver_host(b, "");
  if (r.contains("frames")) print_solver_host(r["frames"], "with frames, ");
  if (h.contains("aspiration")) {
    const nlohmann::json& a = h["aspiration"];
    std::printf(
        "%36s aspiration: %lld reads, s: read %.3f, sphere %.3f, rest map %.3f, "
        "removal %.3f\n",
        "", static_cast<long long>(a["reads"].get<int64_t>()), a["read"].get<double>(),
        a["sphere"].get<double>(), a["rest_map"].get<double>(), a["removal"].get<double>());
  }
  if (r.contains("frames") && r["frames"].contains("frame_host_seconds")) {
    const nlohmann::json& f = r["frames"]["frame_host_seconds"];
    const nlohmann::json& fh = r["frames"]["host_seconds"];
    std::printf(
        "%36s frames: %lld (%lld aspirations), s: wait %.3f, cuts %.3f, aspiration %.3f, video "
        "%.3f, submit %.3f; run loop s with/without: advance %.2f/%.2f, callbacks %.2f/%.2f, "
        "outputs %.2f/%.2f\n",
        "", static_cast<long long>(f["frames"].get<int64_t>()),
        static_cast<long long>(f["aspirations"].get<int64_t>()), f["wait"].get<double>(),
        f["cuts"].get<double>(), f["aspiration"].get<double>(), f["video"].get<double>(),
        f["submit"].get<double>(), fh["advance"].get<double>(), h["advance"].get<double>(),
        fh["callbacks"].get<double>(), h["callbacks"].get<double>(), fh["outputs"].get<double>(),
        h["outputs"].get<double>());
  }
  if (r.contains("frames") && r["frames"].contains("frame_gpu_pass_us"))
    std::printf("%36s frame GPU us per pass (alone): %s\n", "",
                pass_list(r["frames"]["frame_gpu_pass_us"]).c_str());
  std::string outcome;
  for (const auto& [name, v] : b["outcome"].items()) outcome += " " + name + " " + v.dump();
  if (!outcome.empty()) std::printf("%36s outcome:%s\n", "", outcome.c_str());
  if (!b["finite"].get<bool>()) std::printf("%36s (non-finite: the figures mean nothing)\n", "");
  std::fflush(stdout);
}

}  // namespace

int bench_surgery(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--surgery");
  if (opts.flag("--help")) {
    std::puts(kSurgeryHelp);
    return 0;
  }
  SurgeryOptions o;
  o.device = opts.value("--device", "gpu");
  const std::string scenes_text =
      opts.value("--scenes", "scenes/brain_tumour_removal.json,scenes/breast_resection.json");
  const std::vector<double> refinements = parse_refinements(opts.value("--refine", "1,2"));
  o.steps = opts.integer("--steps", -1, 1, int64_t(1) << 40);
  o.width = static_cast<int>(opts.integer("--width", 1920, 16, 8192));
  o.height = static_cast<int>(opts.integer("--height", 1080, 16, 8192));
  o.fps = opts.number("--fps", 60, 1, 1000);
  o.frames = !opts.flag("--no-frames");
  o.profile_steps = opts.integer("--profile-steps", 32, 0, 1 << 16);
  o.profile_parts = opts.flag("--profile-parts");
  o.bare_steps = opts.integer("--bare-steps", 64, 1, 1 << 20);
  o.threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  const std::string out_dir = opts.value("--out", "");
  opts.finish();
  std::vector<std::string> scenes;
  std::stringstream ss(scenes_text);
  for (std::string item; std::getline(ss, item, ',');) scenes.push_back(item);

  std::printf("surgery at several resolutions on %s (frames: stereo %dx%d per eye, %g/s)\n",
              o.device.c_str(), o.width, o.height, o.fps);
  std::printf("%-28s %5s %9s %10s %8s %8s %7s %7s %7s %9s %9s %7s  %s\n", "scene", "K", "phyxels",
              "substep/s", "rt", "rt+frm", "adv s", "chk s", "cb s", "sub us", "box us", "ratio",
              "GPU us per pass");
  nlohmann::json rows = nlohmann::json::array();
  for (const std::string& file : scenes) {
    for (const double k : refinements) {
      rows.push_back(surgery_row(file, k, o));
      print_row(rows.back());
    }
  }
  std::printf(
      "(rt: real-time factor without frames, rt+frm: with the frames; adv, chk, cb: the run "
      "loop's host seconds advancing, checking and in callbacks (aspiration, tools); sub us: "
      "wall time per substep of the run without frames; box us: the bare elastic step of a box "
      "of as many phyxels; ratio: sub over box)\n");
  if (!out_dir.empty())
    write_json_file(std::filesystem::path(out_dir) / "surgery.json", {{"surgery", rows}});
  return 0;
}

}  // namespace phyxel::bench
