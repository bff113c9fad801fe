// phyxel run SCENE: simulate a scene file, write summary.json and .vtp point files.
#include <arpa/inet.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/options.h"
#include "app/run_folder.h"
#include "app/run_report.h"
#include "compute/gpu_solver.h"
#include "engine/run/checkpoint_values.h"
#include "engine/run/simulation.h"
#include "engine/run/tool_trace.h"
#include "engine/surgery/haptic_session.h"
#include "render/frame_output.h"

namespace phyxel::app {
namespace {

constexpr const char* kRunHelp =
    "usage: phyxel run SCENE [options]\n"
    "\n"
    "Simulates SCENE (a JSON scene file, see docs/scene-format.md) and writes DIR/summary.json\n"
    "and DIR/points_NNNNNN.vtp (every output.every steps and always at the end).\n"
    "\n"
    "options:\n"
    "  --device D          solver device: cpu (the double-precision reference solver, default),\n"
    "                      gpu (the best Vulkan device), gpu:N (device N of `phyxel info`) or\n"
    "                      part of a device name; the GPU solver computes in float32\n"
    "  --validate          with a GPU device: Vulkan validation layers on; the run fails\n"
    "                      (exit 1) if they report an error\n"
    "  --steps N           number of steps (default: the scene's simulation.steps)\n"
    "  --refine K          every object's spacing and support radius divided by K (a number\n"
    "                      from 1 to 16; K^3 times the phyxels); tools, paths, materials and\n"
    "                      times unchanged, the substeps follow the stable step\n"
    "  --out DIR           output folder (default: out)\n"
    "  --threads N         CPU threads (default: all cores)\n"
    "  --precision P       double (default) or float, for the CPU solver; float on the GPU\n"
    "  --explain           print the pass plan (what runs per substep, what is skipped and\n"
    "                      why) and exit\n"
    "  --no-skip           run every pass over every phyxel: no skipping of fixed-only\n"
    "                      regions, no sleeping (to check that skipping is exact)\n"
    "  --render MODE       none, mono or stereo: also write DIR/frame_NNNNNN.png at step 0,\n"
    "                      every render.every steps and at the end (default: the scene's\n"
    "                      render.mode); offscreen, never needs a display\n"
    "  --video FILE        also encode the frames as H.264 in an MP4 (mono, or the stereo\n"
    "                      layout), at the simulated-time rate 1 / (render.every x dt);\n"
    "                      renders mono when neither --render nor render.mode says (default:\n"
    "                      the scene's render.video, relative to DIR)\n"
    "  --draw-only         with --render: draw and read back every frame, but write no PNG\n"
    "                      (what drawing costs a run, e.g. with render.every at 60 frames/s)\n"
    "  --render-device D   Vulkan device of the renderer with --device cpu (default gpu);\n"
    "                      with a GPU solver the renderer reads its buffers on its device\n"
    "  --haptic-device D   the device of tools with \"control\": \"haptic\": scripted (their\n"
    "                      path, replayed on the wall clock; default), udp:PORT or\n"
    "                      udp:ADDRESS:PORT (an external device driver, docs/haptics.md); such\n"
    "                      runs are paced to the wall clock and a 1 kHz haptic loop runs;\n"
    "                      the first sender is pinned for the run, others' poses are dropped\n"
    "  --haptic-peer A     with udp: accept poses from IPv4 address A (default: loopback only)\n"
    "  --checkpoint-every N  write DIR/checkpoint.phx (atomically) every N steps and at the\n"
    "                      end, from which --resume continues\n"
    "  --resume DIR        continue the run checkpointed in DIR/checkpoint.phx (same scene,\n"
    "                      device and precision) to the scene's or --steps total, writing into\n"
    "                      DIR; bit-identical to the uninterrupted run (docs/checkpoint.md)\n"
    "  --quiet             no progress bar\n"
    "  --help              this text\n"
    "\n"
    "SIGINT (Ctrl-C) or SIGTERM stops the run after the current step and writes what it has:\n"
    "the last state DIR/points_NNNNNN.vtp, the last frame when rendering, tools.csv and\n"
    "summary.json with \"interrupted\": true and \"interrupted_by\". A second signal ends the\n"
    "process at once, writing nothing more (the files written so far stay whole).\n"
    "\n"
    "exit status: 0 done, 1 bad input or I/O error, 2 bad usage, 3 the simulation became\n"
    "non-finite or ran away, 130 stopped by SIGINT, 143 stopped by SIGTERM";

// A one-line progress bar on a terminal, redrawn at most 10 times a second.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : enabled_(enabled && isatty(fileno(stderr))) {}
  void update(int64_t step, int64_t total) {
    if (!enabled_ || total <= 0) return;
    const auto now = std::chrono::steady_clock::now();
    if (step < total && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double frac = static_cast<double>(step) / static_cast<double>(total);
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double eta = frac > 0 ? elapsed * (1 - frac) / frac : 0;
    const int width = 30, filled = static_cast<int>(frac * width);
    std::fprintf(stderr, "\r[%.*s%.*s] %3d%%  step %lld/%lld  eta %.0f s ", filled,
                 "##############################", width - filled, "..............................",
                 static_cast<int>(frac * 100), static_cast<long long>(step),
                 static_cast<long long>(total), eta);
    if (step >= total) std::fputc('\n', stderr);
    std::fflush(stderr);
  }
  void finish() {
    if (enabled_) std::fputc('\n', stderr);
  }

 private:
  bool enabled_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_{};
};

// A bad --haptic-device or --haptic-peer is bad usage (exit 2) whether or not the scene has a
// haptic tool.
void check_haptic_device_options(const std::string& spec, const std::string& peer) {
  HapticDeviceSpec parsed;
  try {
    parsed = parse_haptic_device_spec(spec);
  } catch (const HapticError& e) {
    throw UsageError(std::string("phyxel run: ") + e.what());
  }
  in_addr addr{};
  if (!peer.empty() && (!parsed.udp || inet_pton(AF_INET, peer.c_str(), &addr) != 1))
    throw UsageError("phyxel run: --haptic-peer " + peer +
                     ": allowed the IPv4 address (a dotted quad) of the one machine whose "
                     "driver may send poses to --haptic-device udp:ADDRESS:PORT");
}

// Poses the UDP haptic devices dropped: other senders while one was pinned, senders not allowed.
void warn_dropped_senders(const HapticSession& haptics) {
  for (const HapticSession::ToolLoop& l : haptics.loops()) {
    const auto* udp = dynamic_cast<const UdpDevice*>(&l.loop->device());
    if (udp == nullptr) continue;
    const UdpDeviceStats u = udp->stats();
    if (u.foreign > 0 || u.refused > 0)
      std::fprintf(stderr,
                   "phyxel run: tool '%s' (%s): dropped %llu poses of other senders while the "
                   "first was pinned and %llu datagrams of senders not allowed (loopback only "
                   "unless --haptic-peer ADDRESS)\n",
                   l.name.c_str(), udp->name().c_str(), (unsigned long long)u.foreign,
                   (unsigned long long)u.refused);
  }
}

// Haptic tools held to their top speed (coupling.max_speed): they lagged their devices.
void warn_speed_limited(const HapticSession& haptics) {
  for (const HapticSession::ToolLoop& l : haptics.loops()) {
    const HapticStats st = l.loop->stats();
    if (st.speed_limited_ticks > 0)
      std::fprintf(stderr,
                   "phyxel run: tool '%s' was held to its top speed, %.3g m/s in simulated time, "
                   "in %llu of %llu haptic ticks, lagging its device (coupling.max_speed, by "
                   "default a tenth of the tissue's slowest p-wave speed: docs/haptics.md)\n",
                   l.name.c_str(), st.top_speed, (unsigned long long)st.speed_limited_ticks,
                   (unsigned long long)st.ticks);
  }
}

// What `phyxel run` was asked on its command line.
struct RunArgs {
  std::string scene_file, device, resume_dir, precision, render_mode, video, render_device;
  std::string haptic_device, haptic_peer;
  std::filesystem::path out_dir;
  int64_t checkpoint_every = 0, steps_override = -1;
  int threads = 0;
  bool gpu = false, validate = false, quiet = false, draw_only = false, explain = false;
  bool no_skip = false;
  double refine = 1;
};

// The options that do not go together; the exit status, or -1 when they do.
int check_run_args(const RunArgs& a) {
  if (a.gpu && a.precision != "float") {
    std::fprintf(stderr,
                 "phyxel run: --precision %s: the GPU solver computes in float32; use --device "
                 "cpu for double\n",
                 a.precision.c_str());
    return 1;
  }
  if (a.validate && !a.gpu) {
    std::fprintf(stderr, "phyxel run: --validate: only with a GPU device (--device gpu)\n");
    return 1;
  }
  if (a.precision != "double" && a.precision != "float") {
    std::fprintf(stderr, "phyxel run: --precision %s: allowed double or float\n",
                 a.precision.c_str());
    return 1;
  }
  if (!a.resume_dir.empty() &&
      std::filesystem::path(a.resume_dir).lexically_normal() != a.out_dir.lexically_normal()) {
    std::fprintf(stderr, "phyxel run: --resume %s writes into that folder; leave out --out\n",
                 a.resume_dir.c_str());
    return 1;
  }
  if (!a.render_mode.empty() && a.render_mode != "none" && a.render_mode != "mono" &&
      a.render_mode != "stereo") {
    std::fprintf(stderr, "phyxel run: --render %s: allowed none, mono or stereo\n",
                 a.render_mode.c_str());
    return 1;
  }
  return -1;
}

// Phase "options": the command line read and checked. Returns the exit status when the command
// ends here (--help, a bad combination), -1 to go on.
int parse_run_args(const Args& args, RunArgs& a) {
  OptionParser opts("run", args);
  if (opts.flag("--help")) {
    std::puts(kRunHelp);
    return 0;
  }
  a.device = opts.value("--device", "cpu");
  a.resume_dir = opts.value("--resume", "");
  a.out_dir = opts.value("--out", a.resume_dir.empty() ? "out" : a.resume_dir);
  a.checkpoint_every = opts.integer("--checkpoint-every", 0, 0, int64_t(1) << 40);
  a.threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  a.gpu = a.device != "cpu";
  a.validate = opts.flag("--validate");
  a.precision = opts.value("--precision", a.gpu ? "float" : "double");
  a.quiet = opts.flag("--quiet");
  a.draw_only = opts.flag("--draw-only");
  a.explain = opts.flag("--explain");
  a.no_skip = opts.flag("--no-skip");
  a.render_mode = opts.value("--render", "");
  a.video = opts.value("--video", "");
  a.render_device = opts.value("--render-device", "gpu");
  a.haptic_device = opts.value("--haptic-device", "scripted");
  a.haptic_peer = opts.value("--haptic-peer", "");
  a.steps_override = opts.integer("--steps", -1, 0, int64_t(1) << 40);
  a.refine = opts.number("--refine", 1, 1, kMaxRefine);
  const std::vector<std::string> positional = opts.finish();
  check_haptic_device_options(a.haptic_device, a.haptic_peer);
  if (positional.size() != 1) {
    std::fprintf(stderr, "phyxel run: expected one SCENE file (see phyxel run --help)\n");
    return 1;
  }
  a.scene_file = positional[0];
  return check_run_args(a);
}

// For a failure's message: the last step the run loop completed (-1: before the run loop,
// while setting up) and the last points file this run wrote.
struct RunProgress {
  int64_t step_reached = -1, steps_total = 0;
  std::string last_points;
};

// One `phyxel run` after its options: scene, folder, solver, the run loop's options and live
// outputs (progress, tools.csv, haptics, frames), the loop, the report. Everything it holds is
// released in the reverse order.
class RunCommand {
 public:
  RunCommand(const RunArgs& args, RunProgress& progress) : a_(args), progress_(progress) {}
  // The exit status.
  int execute();

 private:
  int load_scene_and_folder();
  void make_solver();
  void set_run_options();
  void set_progress();
  void set_haptics();
  void set_frames();
  void set_tool_trace();
  RunResult run();
  int report(const RunResult& result);

  const RunArgs& a_;
  RunProgress& progress_;
  std::unique_ptr<Checkpoint> checkpoint_;
  Scene scene_;
  std::string video_source_;
  PhyxelSet set_;
  std::unique_ptr<OutDirLock> lock_;
  std::unique_ptr<Solver> solver_;
  std::shared_ptr<const gpu::ValidationLog> validation_;
  RunOptions options_;
  TimeStepPlan plan_;
  std::unique_ptr<ProgressBar> bar_;
  // Where the physics had each tool at the end of the last step, for the frames.
  std::vector<render::ToolDrawable> tool_poses_;
  std::unique_ptr<ToolTraceWriter> trace_;
  std::unique_ptr<HapticSession> haptics_;
  std::unique_ptr<render::FrameWriter> frames_;
  std::function<void()> write_first_frame_;  // step 0's frame, once the run is set up
};

int RunCommand::execute() {
  if (const int status = load_scene_and_folder(); status >= 0) return status;
  make_solver();
  set_run_options();
  if (a_.explain) {
    std::fputs(explain_passes(scene_, set_, *solver_, options_).c_str(), stdout);
    return 0;
  }
  set_progress();
  set_haptics();
  set_frames();
  set_tool_trace();
  return report(run());
}

// Phase "scene": the checkpoint first (a bad one is refused before the solver is built), the
// scene as the options change it, its phyxels; the output folder, locked. Returns the exit
// status when the command ends here, -1 to go on.
int RunCommand::load_scene_and_folder() {
  if (!a_.resume_dir.empty())
    checkpoint_ = std::make_unique<Checkpoint>(
        read_checkpoint(std::filesystem::path(a_.resume_dir) / kCheckpointFile));
  scene_ = load_scene(a_.scene_file);
  Scene& scene = scene_;
  const std::string& render_mode = a_.render_mode;
  const std::filesystem::path& out_dir = a_.out_dir;
  refine_scene(scene, a_.refine);
  if (!render_mode.empty())
    scene.render.mode = render_mode == "mono"     ? RenderSettings::Mode::Mono
                        : render_mode == "stereo" ? RenderSettings::Mode::Stereo
                                                  : RenderSettings::Mode::None;
  video_source_ = scene.file.string() + ": render.video";
  if (!a_.video.empty()) {
    scene.render.video = a_.video;
    video_source_ = "phyxel run: --video";
  } else if (!scene.render.video.empty()) {
    scene.render.video = out_dir / scene.render.video;
  }
  if (!scene.render.video.empty() && scene.render.mode == RenderSettings::Mode::None &&
      render_mode.empty())
    scene.render.mode = RenderSettings::Mode::Mono;
  set_ = sample_scene(scene);
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    std::fprintf(stderr, "phyxel run: --out %s: cannot create the folder (%s)\n", out_dir.c_str(),
                 ec.message().c_str());
    return 1;
  }
  // One run at a time in a folder; released (the lock file removed) when the command returns.
  lock_ = std::make_unique<OutDirLock>(out_dir);
  if (lock_->stale_pid() > 0)
    std::fprintf(stderr,
                 "phyxel run: %s: took over the lock of process %ld, which ended without "
                 "releasing it\n",
                 (out_dir / kLockFile).c_str(), lock_->stale_pid());
  return -1;
}

// Phase "solver": CPU or GPU, checked against the checkpoint before anything in the folder
// changes.
void RunCommand::make_solver() {
  if (a_.gpu) {
    gpu::ContextOptions context;
    context.device = a_.device;
    context.validation = a_.validate;
    solver_ = make_gpu_solver(set_, scene_.simulation.gravity, context);
    validation_ = static_cast<gpu::GpuSolver&>(*solver_).context().validation_log();
  } else {
    solver_ = make_cpu_solver(set_, scene_.simulation.gravity, a_.threads, a_.precision == "float");
  }
  if (checkpoint_) {
    const std::filesystem::path file = std::filesystem::path(a_.resume_dir) / kCheckpointFile;
    check_checkpoint_matches(*checkpoint_, file, file_hash(scene_.file), set_, solver_->device());
    check_checkpoint_values(*checkpoint_, file, scene_, set_);
  }
}

void RunCommand::set_run_options() {
  options_.steps = a_.steps_override >= 0 ? a_.steps_override : scene_.simulation.steps;
  options_.out_dir = a_.out_dir;
  options_.pass_selection = !a_.no_skip;
  options_.on_points_written = [this](const std::string& name) { progress_.last_points = name; };
  options_.resume = checkpoint_.get();
  options_.checkpoint_every = a_.checkpoint_every > 0 ? a_.checkpoint_every
                              : checkpoint_           ? checkpoint_->checkpoint_every
                                                      : 0;
}

// Said before the run, which may take long: how each step is split; then its progress, and
// how long a run of long steps will take.
void RunCommand::set_progress() {
  plan_ = plan_time_step(scene_, set_);
  if (!plan_.reason.empty()) std::fprintf(stderr, "phyxel run: %s\n", plan_.reason.c_str());
  options_.on_substep_rate = [this](double rate) {
    const double substeps = double(options_.steps) * double(plan_.substeps);
    std::fprintf(stderr,
                 "phyxel run: about %.3g s of wall time for %lld steps (%.3g substeps per "
                 "second, measured on the first); Ctrl-C stops it within a fraction of a "
                 "second\n",
                 substeps / rate, static_cast<long long>(options_.steps), rate);
  };
  options_.stop_requested = [] { return InterruptGuard::received() != 0; };
  bar_ = std::make_unique<ProgressBar>(!a_.quiet);
  options_.progress = [this](int64_t s, int64_t t) {
    progress_.step_reached = s;
    bar_->update(s, t);
  };
}

// Tools: haptic tools get a 1 kHz loop each and the run is paced to the wall clock.
void RunCommand::set_haptics() {
  tool_poses_ = render::tool_drawables(scene_.tools, 0.0);
  haptics_ = std::make_unique<HapticSession>(scene_, a_.haptic_device, a_.haptic_peer);
  if (haptics_->empty() && a_.haptic_device != "scripted")
    std::fprintf(stderr,
                 "phyxel run: --haptic-device %s: %s has no tool with \"control\": "
                 "\"haptic\"; the device is not used\n",
                 a_.haptic_device.c_str(), scene_.file.c_str());
  if (!haptics_->empty()) {
    options_.tool_pose = haptics_->pose_source();
    options_.real_time = true;
  }
}

// Frames: from the GPU solver's buffers on its context, or from the CPU solver's state; at
// step 0, then scheduled by the run loop every render.every steps and at the end.
void RunCommand::set_frames() {
  if (scene_.render.mode == RenderSettings::Mode::None) return;
  const Scene& scene = scene_;
  auto* gpu_solver = dynamic_cast<gpu::GpuSolver*>(solver_.get());
  render::FrameWriterOptions frame_options;
  frame_options.mode = scene.render.mode;
  frame_options.out_dir = a_.out_dir;
  frame_options.device = a_.render_device;
  frame_options.write_files = !a_.draw_only;
  frame_options.video = scene.render.video;
  frame_options.video_every = scene.render.every;
  frame_options.video_fps = 1.0 / (double(scene.render.every) * scene.simulation.dt);
  frame_options.video_source = video_source_;
  frames_ = std::make_unique<render::FrameWriter>(scene, set_, frame_options,
                                                  gpu_solver ? &gpu_solver->context() : nullptr);
  std::function<render::RenderInputs()> buffers;
  if (gpu_solver) buffers = [gpu_solver] { return gpu_solver->buffers(); };
  write_first_frame_ = [this, buffers] {
    render::write_solver_frame(*frames_, *solver_, 0, tool_poses_, buffers);
  };
  options_.frame_every = scene.render.every;
  options_.on_frame = [this, buffers](int64_t step, Solver& s) {
    render::write_solver_frame(*frames_, s, step, tool_poses_, buffers);
  };
  // From the GPU solver's buffers only: drawn inside the advances (RunOptions).
  options_.frames_within_advance = gpu_solver != nullptr;
  options_.on_frame_tool_poses = [this](const std::vector<ToolPose>& poses) {
    for (size_t k = 0; k < poses.size() && k < tool_poses_.size(); ++k)
      tool_poses_[k].pose = poses[k];
  };
  // Aspirated tissue leaves the frames; the crater's wall is drawn as fracture surface.
  options_.on_aspiration = [this](const AspirationEvent& e) { frames_->apply_aspiration(e); };
}

// Everything that can refuse the run has been set up: from here on the folder changes. Tools:
// DIR/tools.csv, a row per step and tool.
void RunCommand::set_tool_trace() {
  const std::vector<std::string> stale = remove_stale_temp_files(a_.out_dir);
  if (!stale.empty())
    std::fprintf(stderr,
                 "phyxel run: removed %zu temporary file%s of an earlier run that was killed "
                 "(%s%s)\n",
                 stale.size(), stale.size() == 1 ? "" : "s", stale.front().c_str(),
                 stale.size() > 1 ? ", ..." : "");
  if (scene_.tools.empty()) return;
  trace_ = std::make_unique<ToolTraceWriter>(a_.out_dir / "tools.csv", scene_.tools,
                                             checkpoint_ ? checkpoint_->step : -1,
                                             options_.checkpoint_every > 0);
  options_.before_checkpoint = [this] { trace_->flush(); };
  options_.on_tool_step = [this](int64_t step, double t,
                                 const std::vector<ToolStepRecord>& records) {
    if (!haptics_->empty()) haptics_->publish(t, records);
    trace_->write(step, t, records);
    for (size_t k = 0; k < records.size(); ++k) tool_poses_[k].pose = records[k].pose;
  };
}

// Phase "loop": the run loop to the end, then the live outputs closed (haptic loops, tools.csv,
// the frames' writer thread and video) before the solver, which may own their context.
RunResult RunCommand::run() {
  if (frames_ && !checkpoint_) write_first_frame_();
  haptics_->start();
  progress_.step_reached = 0;
  progress_.steps_total = options_.steps;
  RunResult result = run_simulation(scene_, set_, *solver_, options_);
  haptics_->stop();
  warn_dropped_senders(*haptics_);
  warn_speed_limited(*haptics_);
  if (trace_) {
    trace_->close();
    result.outputs.push_back("tools.csv");
  }
  return result;
}

// Phase "report": summary.json, then what the run says and its exit status.
int RunCommand::report(const RunResult& result) {
  const Scene& scene = scene_;
  const std::filesystem::path& out_dir = a_.out_dir;
  if (frames_) frames_->finish();  // the writer thread's last PNG files and the video
  const size_t frame_count = frames_ ? frames_->written().size() : 0;
  options_.on_frame = nullptr;
  options_.on_aspiration = nullptr;
  frames_.reset();  // before the solver: it may own the context
  if (result.steps_done < options_.steps) bar_->finish();
  // A signal that came during the run (or while its last outputs were written) is reported.
  const int signal = InterruptGuard::received();
  write_run_summary(out_dir / "summary.json", scene, set_, *solver_, options_, result,
                    haptics_.get(), signal != 0 ? signal_name(signal) : nullptr);
  if (options_.real_time && result.real_time_factor < 0.99)
    std::fprintf(stderr,
                 "phyxel run: the simulation ran at %.2fx real time (fell behind the wall clock "
                 "by up to %.3f s); haptic forces lagged accordingly. Use a coarser scene or "
                 "--device gpu\n",
                 result.real_time_factor, result.max_lag);
  const std::string device_name = solver_->device();
  solver_.reset();  // the validation layer also checks the teardown
  if (validation_ != nullptr) {
    std::fprintf(stderr, "phyxel run: Vulkan validation: %s\n", validation_->summary().c_str());
    if (validation_->error_count() > 0) return 1;
  }
  if (const std::string stop = describe_stop(scene, result); !stop.empty()) {
    std::fprintf(stderr, "phyxel run: %s\n", stop.c_str());
    return 3;
  }
  if (signal != 0) {
    std::fprintf(stderr,
                 "phyxel run: %s: stopped by %s after step %lld of %lld; wrote %s%s (exit "
                 "status %d)\n",
                 scene.file.c_str(), signal_name(signal), static_cast<long long>(result.steps_done),
                 static_cast<long long>(options_.steps),
                 progress_.last_points.empty() ? "" : "the last state and ",
                 (out_dir / "summary.json").c_str(), interrupted_exit_status(signal));
    return interrupted_exit_status(signal);
  }
  if (!a_.quiet)
    std::printf("%s: %zu phyxels, %lld steps%s in %.2f s on %s; wrote %s\n", scene.file.c_str(),
                set_.size(), static_cast<long long>(result.steps_done),
                result.stopped_at_rest ? " (stopped at rest)" : "", result.wall_seconds,
                device_name.c_str(), (out_dir / "summary.json").c_str());
  if (!a_.quiet && frame_count > 0)
    std::printf("wrote %zu frames frame_NNNNNN.png to %s\n", frame_count, out_dir.c_str());
  if (!a_.quiet && !scene.render.video.empty())
    std::printf("wrote the video %s\n", scene.render.video.c_str());
  return 0;
}

}  // namespace

int run_command(const Args& args) {
  RunArgs a;
  if (const int status = parse_run_args(args, a); status >= 0) return status;
  // SIGINT and SIGTERM from here on stop the run cleanly (app/interrupt.h); the previous
  // handlers come back when the command returns.
  const InterruptGuard interrupts;
  RunProgress progress;
  try {
    RunCommand command(a, progress);
    return command.execute();
  } catch (const SearchStopped& e) {  // a signal while setting up: nothing was written
    const int signal = InterruptGuard::received();
    std::fprintf(stderr, "phyxel run: %s: %s by %s; wrote nothing (exit status %d)\n",
                 a.scene_file.c_str(), e.what(), signal_name(signal),
                 interrupted_exit_status(signal));
    return interrupted_exit_status(signal);
  } catch (const CheckpointError& e) {
    std::fprintf(stderr, "phyxel run: %s\n", e.what());
    return 1;
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  } catch (const VulkanError& e) {
    // No loader or driver, no such device, not enough GPU memory, a lost device: one line with
    // the step reached. Output files written before a failure stay whole (the writers replace
    // files atomically).
    std::string when = "while setting up";
    if (progress.step_reached >= 0)
      when = "after step " + std::to_string(progress.step_reached) + " of " +
             std::to_string(progress.steps_total);
    std::fprintf(stderr, "phyxel run: %s %s: %s%s; %s\n", a.scene_file.c_str(), when.c_str(),
                 e.what(),
                 e.result() == VK_ERROR_DEVICE_LOST ? " (the GPU was lost; the run stopped)" : "",
                 progress.last_points.empty() ? "no points file was written"
                                              : ("the outputs written before are intact (the "
                                                 "last: " +
                                                 progress.last_points + ")")
                                                    .c_str());
    return 1;
  }
}

}  // namespace phyxel::app
