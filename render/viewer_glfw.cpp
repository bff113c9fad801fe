// The window viewer (PHYXEL_WITH_WINDOW): the CPU reference solver advanced live, frames from
// the splat renderer (headless context, as `phyxel run --render`) shown through Presenter.
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "engine/surgery/haptic_session.h"
#include "render/frame_output.h"
#include "render/image.h"
#include "render/present_glfw.h"
#include "render/real_time_pacer.h"
#include "render/viewer.h"
#include "render/viewer_controls.h"

namespace phyxel::render {
namespace {

constexpr const char* kHeadless =
    "for frames without a display use: phyxel run SCENE --render mono|stereo --out DIR";

ViewerControls& controls_of(GLFWwindow* w) {
  return *static_cast<ViewerControls*>(glfwGetWindowUserPointer(w));
}

// p: the frame just shown as DIR/view-STEP.png (view-STEP-K.png when taken before). A picture
// that cannot be written is reported, and the viewer goes on.
void save_picture(const std::filesystem::path& dir, int64_t step, const RgbaImage& frame) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::string stem = "view-" + std::to_string(step);
  std::filesystem::path file = dir / (stem + ".png");
  for (int k = 2; std::filesystem::exists(file, ec); ++k)
    file = dir / (stem + "-" + std::to_string(k) + ".png");
  try {
    write_png(file, frame);
    std::printf("phyxel view: saved %s (%ux%u)\n", file.c_str(), frame.width, frame.height);
    std::fflush(stdout);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "phyxel view: the picture was not saved: %s\n", e.what());
  }
}

ViewerKey key_of(int key) {
  switch (key) {
    case GLFW_KEY_SPACE:
      return ViewerKey::Space;
    case GLFW_KEY_N:
      return ViewerKey::N;
    case GLFW_KEY_S:
      return ViewerKey::S;
    case GLFW_KEY_P:
      return ViewerKey::P;
    case GLFW_KEY_Q:
      return ViewerKey::Q;
    case GLFW_KEY_ESCAPE:
      return ViewerKey::Escape;
    default:
      return ViewerKey::Other;
  }
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  ViewerControls& c = controls_of(w);
  c.key(key_of(key));
  if (c.quit()) glfwSetWindowShouldClose(w, GLFW_TRUE);
}

void on_button(GLFWwindow* w, int button, int action, int mods) {
  if (button != GLFW_MOUSE_BUTTON_LEFT && button != GLFW_MOUSE_BUTTON_RIGHT) return;
  // Where the cursor events processed so far put the cursor: glfwGetCursorPos would ask the X
  // server for the pointer now, past motion events still queued behind this press.
  ViewerControls& controls = controls_of(w);
  const Eigen::Vector2d at = controls.cursor_position();
  controls.button(button == GLFW_MOUSE_BUTTON_LEFT ? ViewerButton::Left : ViewerButton::Right,
                  action == GLFW_PRESS, at.x(), at.y(), (mods & GLFW_MOD_SHIFT) != 0);
}

void on_cursor(GLFWwindow* w, double x, double y) {
  controls_of(w).cursor(x, y);
}

void on_scroll(GLFWwindow* w, double, double dy) {
  const bool shift = glfwGetKey(w, GLFW_KEY_LEFT_SHIFT) == GLFW_PRESS ||
                     glfwGetKey(w, GLFW_KEY_RIGHT_SHIFT) == GLFW_PRESS;
  controls_of(w).scroll(dy, shift);
}

// Empty while the state is finite and no phyxel outruns its material's wave speed; else what
// happened (also printed once to standard error, with what to try).
std::string stability_problem(const PhyxelSet& set, Solver& solver, int64_t step) {
  char text[256];
  if (const long bad = solver.first_non_finite(); bad >= 0) {
    std::snprintf(text, sizeof text, "halted: non-finite at step %lld, phyxel %ld",
                  static_cast<long long>(step), bad);
  } else if (const Runaway r = find_runaway(set, solver.read_state(false).velocity);
             r.phyxel >= 0) {
    std::snprintf(text, sizeof text, "halted: runaway at step %lld, phyxel %ld (%.3g m/s)",
                  static_cast<long long>(step), r.phyxel, r.speed);
  } else {
    return {};
  }
  std::fprintf(stderr,
               "phyxel view: %s; the simulation is unstable: try a smaller simulation.courant "
               "or dt, or smaller loads\n",
               text);
  return text;
}

}  // namespace

bool viewer_available() {
  return true;
}

void run_viewer(const Scene& source, const ViewerOptions& options) {
  const std::string file = source.file.empty() ? std::string("<scene>") : source.file.string();
  if (glfwInit() != GLFW_TRUE) {
    const char* why = nullptr;
    glfwGetError(&why);
    throw std::runtime_error(file + ": phyxel view: no display (" +
                             std::string(why ? why : "GLFW cannot start") + "); " + kHeadless);
  }
  struct Terminate {
    ~Terminate() { glfwTerminate(); }
  } terminate;
  if (glfwVulkanSupported() != GLFW_TRUE) {
    throw std::runtime_error(file + ": phyxel view: no display with Vulkan presentation; " +
                             kHeadless);
  }
  Scene scene = source;
  if (options.mode) scene.render.mode = *options.mode;
  if (scene.render.mode == RenderSettings::Mode::None)
    scene.render.mode = RenderSettings::Mode::Mono;
  RenderSettings::Mode mode = scene.render.mode;

  const PhyxelSet set = sample_scene(scene);
  const TimeStepPlan plan = plan_time_step(scene, set);
  const bool on_gpu = options.device != "cpu";
  gpu::ContextOptions context;
  context.device = on_gpu ? options.device : options.render_device;
  context.validation = options.validation;
  gpu::Context ctx(context);
  // The GPU solver shares the renderer's context: frames read its buffers where they are.
  std::unique_ptr<gpu::GpuSolver> gpu_solver;
  std::unique_ptr<Solver> cpu_solver;
  std::unique_ptr<HostInputs> host;
  size_t alive_at = 0;  // the CPU solver's severed count when its alive mask was last uploaded
  if (on_gpu) {
    gpu_solver = std::make_unique<gpu::GpuSolver>(ctx, set, scene.simulation.gravity);
  } else {
    cpu_solver = make_cpu_solver(set, scene.simulation.gravity, options.threads);
    host = std::make_unique<HostInputs>(ctx, set, cpu_solver->neighbours());
  }
  Solver& solver = on_gpu ? static_cast<Solver&>(*gpu_solver) : *cpu_solver;
  FrameWriter writer(scene, set, {mode, {}, context.device}, &ctx);

  const int eyes = mode == RenderSettings::Mode::Stereo &&
                           scene.render.stereo.layout == StereoSettings::Layout::SideBySide
                       ? 2
                       : 1;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  GLFWwindow* window = glfwCreateWindow(scene.render.width * eyes, scene.render.height,
                                        ("phyxel view " + file).c_str(), nullptr, nullptr);
  if (window == nullptr) {
    throw std::runtime_error(file + ": phyxel view: cannot open a window; " + kHeadless);
  }
  struct Destroy {
    GLFWwindow* w;
    ~Destroy() { glfwDestroyWindow(w); }
  } destroy{window};
  Presenter presenter(window);
  ViewerControls controls(writer.camera());
  const std::vector<HapticTarget> haptic = haptic_targets(scene.tools);
  // Haptic tools follow the mouse: each has a device whose pose the drags set, and a 1 kHz
  // haptic loop couples the simulated tool to it (engine/surgery/haptic_session.h).
  std::vector<std::shared_ptr<SharedPoseDevice>> mice(scene.tools.size());
  for (size_t t = 0; t < scene.tools.size(); ++t) mice[t] = std::make_shared<SharedPoseDevice>();
  HapticSession haptics(scene, [&mice](size_t tool) { return mice[tool]; });
  auto drag = [&](size_t tool, const ToolPose& target) {
    mice[tool]->set_pose(target);
    if (options.on_tool_drag) options.on_tool_drag(tool, target);
  };
  for (const HapticTarget& h : haptic) drag(h.tool, h.pose);
  auto haptic_pose = [&](size_t tool, const ToolPose& target) {
    if (options.haptic_pose) return options.haptic_pose(tool, target);
    return haptics.pose_source()(tool, 0.0);
  };
  ToolTrack track(scene.tools, haptics.empty() ? ToolTrack::PoseSource{} : haptics.pose_source());
  // Aspirators aspirate as in run_simulation (engine/surgery/aspiration.h), between advances.
  Aspirator aspirator(scene, set);
  if (aspirator.active() && !solver.removal())
    throw std::runtime_error(solver.device() + " cannot remove aspirated tissue");
  if (!scene.tools.empty())
    need(solver.tools(), solver, "simulate tools").set_tools(contact_tools(scene.tools));
  // Tearing (as run_simulation): the largest principal stress every substep.
  if (PrincipalStress* principal = solver.principal_stress())
    principal->set_principal_stress(scene.tearing_possible());
  haptics.start();
  controls.set_haptic_tools(haptic);
  glfwSetWindowUserPointer(window, &controls);
  glfwSetKeyCallback(window, on_key);
  glfwSetMouseButtonCallback(window, on_button);
  glfwSetCursorPosCallback(window, on_cursor);
  glfwSetScrollCallback(window, on_scroll);
  std::printf(
      "phyxel view: %s, %zu phyxels, simulating on %s, rendering on %s, showing on %s\n"
      "  drag: orbit, wheel: zoom, space: pause, n: one step, s: mono/stereo, p: picture, q: quit\n"
      "%s",
      file.c_str(), set.size(), solver.device().c_str(), ctx.info().name.c_str(),
      presenter.device_name().c_str(),
      haptic.empty() ? ""
                     : "  haptic tools: right drag (or shift + drag): move in the view plane, "
                       "shift + wheel: push along the view\n");
  std::fflush(stdout);

  int64_t step = 0;
  const auto start = std::chrono::steady_clock::now();
  auto wall = [&start] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  // Simulated time follows the wall clock, at most 0.1 s of it per frame (so frame rates down
  // to 10 per second keep up).
  const double step_time = scene.simulation.dt;
  RealTimePacer pacer(step_time,
                      std::max<int64_t>(scene.render.every, static_cast<int64_t>(0.1 / step_time)));
  double real_time = 0;
  std::vector<ToolStepRecord> felt;  // what each tool felt in the last step
  auto last_title = std::chrono::steady_clock::now();
  int frames = 0;
  std::string halted;  // why the simulation stopped (non-finite or runaway), empty while fine
  constexpr double kMaxAdvanceSeconds = 0.2;
  double seconds_per_step = 0;  // wall time per step of the last advance
  auto stopping = [&options] { return options.stop_requested && options.stop_requested(); };
  while (glfwWindowShouldClose(window) != GLFW_TRUE && !stopping()) {
    glfwPollEvents();
    if (controls.take_stereo_toggle()) {
      mode = mode == RenderSettings::Mode::Stereo ? RenderSettings::Mode::Mono
                                                  : RenderSettings::Mode::Stereo;
    }
    const int64_t due = pacer.steps_due(wall(), !controls.paused() && halted.empty());
    int64_t advance = controls.paused() ? controls.steps_for_frame(1) : due;
    if (!controls.paused()) controls.steps_for_frame(1);  // consumes a stray n
    // Keys and the window are handled between advances: on a slow device (lavapipe), advance no
    // more than about kMaxAdvanceSeconds of wall time per frame at the rate measured so far (one
    // step until it is measured), so the viewer answers within a fraction of a second however
    // far behind it is.
    if (seconds_per_step <= 0)
      advance = std::min<int64_t>(advance, 1);  // the first advance measures the rate
    else
      advance = std::min<int64_t>(
          advance,
          std::max<int64_t>(1, static_cast<int64_t>(kMaxAdvanceSeconds / seconds_per_step)));
    if (advance > 0 && halted.empty()) {
      const double advance_start = wall();
      const std::vector<ToolStepRecord> records =
          advance_with_tools(solver, track, step, advance, plan.substeps, plan.dt_used);
      seconds_per_step = (wall() - advance_start) / double(advance);
      step += advance;
      pacer.advanced(advance);
      for (const AspirationEvent& e :
           aspirator.after_advance(solver, track.poses(), double(step) * step_time)) {
        writer.apply_aspiration(e);
        alive_at = std::numeric_limits<size_t>::max();  // the CPU's pair mask changed
      }
      if (!records.empty()) {
        felt.assign(records.end() - scene.tools.size(), records.end());
        if (!haptics.empty()) haptics.publish(double(step) * step_time, felt);
      }
    }
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    if (fw <= 0 || fh <= 0) {
      glfwWaitEventsTimeout(0.1);  // minimised: wake up to poll stop_requested
      continue;
    }
    RenderSettings r = scene.render;
    const bool side_by_side = mode == RenderSettings::Mode::Stereo &&
                              r.stereo.layout == StereoSettings::Layout::SideBySide;
    r.width = std::max(1, side_by_side ? fw / 2 : fw);
    r.height = fh;
    int ww = 0, wh = 0;  // the cursor's units (differ from the framebuffer's on HiDPI)
    glfwGetWindowSize(window, &ww, &wh);
    controls.set_view_size(side_by_side ? ww / 2.0 : ww, wh);
    for (const size_t k : controls.take_moved_tools()) {
      const HapticTarget& h = controls.haptic_tools()[k];
      drag(h.tool, h.pose);
    }
    writer.set_setup(make_frame_setup(controls.orbit().camera(writer.camera()), r, mode));
    if (!scene.tools.empty()) {
      writer.set_tools(viewer_tools(scene.tools, double(step) * scene.simulation.dt,
                                    controls.haptic_tools(), haptic_pose));
    }
    // Cuts since the last frame: cut-face surfels; the GPU solver's buffers carry its pair
    // weights, the CPU solver's alive mask is uploaded when its severed count changed.
    writer.follow_cuts(solver, false);
    // The video texture: the newest frame decoded by now (never waits for the decoder).
    writer.advance_video(double(step) * scene.simulation.dt, false);
    RgbaImage frame;
    if (on_gpu) {
      frame = writer.render(gpu_solver->buffers());
    } else {
      if (const size_t severed = severed_pair_count(solver); severed != alive_at) {
        host->set_pair_alive(alive_pairs(solver));
        alive_at = severed;
      }
      host->set_displacement(cpu_solver->read_state(false).displacement);
      frame = writer.render(host->inputs());
    }
    presenter.present(frame);
    if (controls.take_screenshot()) save_picture(options.picture_dir, step, frame);
    ++frames;
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_title).count();
    if (seconds > 0.5) {
      if (halted.empty()) halted = stability_problem(set, solver, step);
      real_time = pacer.factor();
      std::string note = halted;
      for (size_t t = 0; t < felt.size() && halted.empty(); ++t) {
        char text[128];
        std::snprintf(text, sizeof text, "%s%s %.3f N (%u contacts)", note.empty() ? "" : ", ",
                      scene.tools[t].name.c_str(), felt[t].force.norm(), felt[t].contacts);
        note += text;
      }
      if (const size_t cut = severed_pair_count(solver); cut > 0 && halted.empty())
        note += (note.empty() ? "" : ", ") + std::to_string(cut) + " pairs cut";
      glfwSetWindowTitle(
          window, viewer_title(file, step, controls.paused(), mode == RenderSettings::Mode::Stereo,
                               frames / seconds, note, controls.paused() ? -1 : real_time)
                      .c_str());
      frames = 0;
      last_title = now;
    }
  }
}

}  // namespace phyxel::render
