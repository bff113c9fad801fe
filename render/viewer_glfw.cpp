// The window viewer (PHYXEL_WITH_WINDOW): the CPU reference or GPU solver advanced live by the
// run loop of `phyxel run` (render/viewer_simulation.h), frames from the splat renderer
// (headless context, as `phyxel run --render`) shown through Presenter.
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
#include "engine/surgery/haptic_session.h"
#include "render/frame_output.h"
#include "render/image.h"
#include "render/present_glfw.h"
#include "render/real_time_pacer.h"
#include "render/viewer.h"
#include "render/viewer_controls.h"
#include "render/viewer_simulation.h"

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

// glfwInit with Vulkan presentation, or a one-line error naming the scene file; glfwTerminate
// when it goes.
struct GlfwSession {
  explicit GlfwSession(const std::string& file) {
    if (glfwInit() != GLFW_TRUE) {
      const char* why = nullptr;
      glfwGetError(&why);
      throw std::runtime_error(file + ": phyxel view: no display (" +
                               std::string(why ? why : "GLFW cannot start") + "); " + kHeadless);
    }
    if (glfwVulkanSupported() != GLFW_TRUE) {
      glfwTerminate();
      throw std::runtime_error(file + ": phyxel view: no display with Vulkan presentation; " +
                               kHeadless);
    }
  }
  ~GlfwSession() { glfwTerminate(); }
  GlfwSession(const GlfwSession&) = delete;
  GlfwSession& operator=(const GlfwSession&) = delete;
};

// The scene as the viewer shows it: options.mode over the scene's, mono when it has none.
Scene viewer_scene(const Scene& source, const ViewerOptions& options) {
  Scene scene = source;
  if (options.mode) scene.render.mode = *options.mode;
  if (scene.render.mode == RenderSettings::Mode::None)
    scene.render.mode = RenderSettings::Mode::Mono;
  return scene;
}

// The solver: the GPU solver on the renderer's context (frames read its buffers where they
// are), or the CPU solver with the host inputs its state is uploaded to for each frame.
struct ViewerSolver {
  ViewerSolver(gpu::Context& ctx, const Scene& scene, const PhyxelSet& set,
               const ViewerOptions& options) {
    if (options.device != "cpu") {
      gpu = std::make_unique<gpu::GpuSolver>(ctx, set, scene.simulation.gravity);
    } else {
      cpu = make_cpu_solver(set, scene.simulation.gravity, options.threads);
      host = std::make_unique<HostInputs>(ctx, set, cpu->neighbours());
    }
  }
  Solver& solver() { return gpu ? static_cast<Solver&>(*gpu) : *cpu; }
  // The frame of the solver's state now.
  RgbaImage render(FrameWriter& writer) {
    if (gpu) return writer.render(gpu->buffers());
    if (const size_t severed = severed_pair_count(*cpu); severed != alive_at) {
      host->set_pair_alive(alive_pairs(*cpu));
      alive_at = severed;
    }
    host->set_displacement(cpu->read_state(false).displacement);
    return writer.render(host->inputs());
  }

  std::unique_ptr<gpu::GpuSolver> gpu;
  std::unique_ptr<Solver> cpu;
  std::unique_ptr<HostInputs> host;
  size_t alive_at = 0;  // the CPU solver's severed count when its alive mask was last uploaded
};

// The window, side by side eyes next to each other; destroyed when it goes.
struct ViewerWindow {
  ViewerWindow(const Scene& scene, const std::string& file) {
    const int eyes = scene.render.mode == RenderSettings::Mode::Stereo &&
                             scene.render.stereo.layout == StereoSettings::Layout::SideBySide
                         ? 2
                         : 1;
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    window = glfwCreateWindow(scene.render.width * eyes, scene.render.height,
                              ("phyxel view " + file).c_str(), nullptr, nullptr);
    if (window == nullptr) {
      throw std::runtime_error(file + ": phyxel view: cannot open a window; " + kHeadless);
    }
  }
  ~ViewerWindow() { glfwDestroyWindow(window); }
  ViewerWindow(const ViewerWindow&) = delete;
  ViewerWindow& operator=(const ViewerWindow&) = delete;
  GLFWwindow* window = nullptr;
};

// Haptic tools follow the mouse: each has a device whose pose the drags set, and a 1 kHz
// haptic loop couples the simulated tool to it (engine/surgery/haptic_session.h).
struct MouseTools {
  MouseTools(const Scene& scene, const ViewerOptions& options)
      : options(options),
        targets(haptic_targets(scene.tools)),
        mice(make_mice(scene)),
        haptics(scene, [this](size_t tool) { return mice[tool]; }),
        limited_seen(haptics.loops().size(), 0) {
    for (const HapticTarget& h : targets) drag(h.tool, h.pose);
  }
  static std::vector<std::shared_ptr<SharedPoseDevice>> make_mice(const Scene& scene) {
    std::vector<std::shared_ptr<SharedPoseDevice>> mice(scene.tools.size());
    for (auto& m : mice) m = std::make_shared<SharedPoseDevice>();
    return mice;
  }
  void drag(size_t tool, const ToolPose& target) {
    mice[tool]->set_pose(target);
    if (options.on_tool_drag) options.on_tool_drag(tool, target);
  }
  // Where to draw a haptic tool.
  ToolPose pose(size_t tool, const ToolPose& target) const {
    if (options.haptic_pose) return options.haptic_pose(tool, target);
    return haptics.pose_source()(tool, 0.0);
  }

  // Per scene tool: its top speed where its haptic loop held it there since the last call
  // (it lags the hand), else 0.
  std::vector<double> lagging_since_last() {
    std::vector<double> lagging(mice.size(), 0.0);  // a mouse per scene tool
    for (size_t k = 0; k < haptics.loops().size(); ++k) {
      const HapticStats st = haptics.loops()[k].loop->stats();
      if (st.speed_limited_ticks > limited_seen[k]) lagging[haptics.loops()[k].tool] = st.top_speed;
      limited_seen[k] = st.speed_limited_ticks;
    }
    return lagging;
  }

  const ViewerOptions& options;
  const std::vector<HapticTarget> targets;
  std::vector<std::shared_ptr<SharedPoseDevice>> mice;
  HapticSession haptics;
  std::vector<uint64_t> limited_seen;  // per loop: speed_limited_ticks at the last call
};

// The viewer: everything `phyxel view` holds, built in this order. run() shows frames until the
// window closes: events, the steps the frame owes, the simulation advanced, the frame drawn
// and shown, the title twice a second.
class Viewer {
 public:
  Viewer(const Scene& source, const ViewerOptions& options)
      : options_(options),
        file_(source.file.empty() ? std::string("<scene>") : source.file.string()),
        glfw_(file_),
        scene_(viewer_scene(source, options)),
        set_(sample_scene(scene_)),
        render_device_(options.device != "cpu" ? options.device : options.render_device),
        ctx_(context_options(render_device_, options)),
        solver_(ctx_, scene_, set_, options),
        writer_(scene_, set_, {scene_.render.mode, {}, render_device_}, &ctx_),
        window_(scene_, file_),
        presenter_(window_.window),
        controls_(writer_.camera()),
        tools_(scene_, options),
        sim_(scene_, set_, solver_.solver(), hooks()),
        mode_(scene_.render.mode),
        // Simulated time follows the wall clock, at most 0.1 s of it per frame (so frame
        // rates down to 10 per second keep up).
        pacer_(scene_.simulation.dt,
               std::max<int64_t>(scene_.render.every, static_cast<int64_t>(0.1 / step_time()))) {}

  void run();

 private:
  static gpu::ContextOptions context_options(const std::string& device,
                                             const ViewerOptions& options) {
    gpu::ContextOptions context;
    context.device = device;
    context.validation = options.validation;
    return context;
  }
  ViewerSimulation::Hooks hooks();
  void start();
  int64_t steps_for_frame();
  void advance(int64_t steps);
  bool draw();
  void update_title();
  double step_time() const { return scene_.simulation.dt; }
  double wall() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

  const ViewerOptions& options_;
  const std::string file_;
  const GlfwSession glfw_;
  const Scene scene_;
  const PhyxelSet set_;
  const std::string render_device_;
  gpu::Context ctx_;
  ViewerSolver solver_;
  FrameWriter writer_;
  ViewerWindow window_;
  Presenter presenter_;
  ViewerControls controls_;
  MouseTools tools_;
  ViewerSimulation sim_;
  RenderSettings::Mode mode_;
  RealTimePacer pacer_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double seconds_per_step_ = 0;  // wall time per step of the last advance
  std::chrono::steady_clock::time_point last_title_ = std::chrono::steady_clock::now();
  int frames_ = 0;
};

// What the simulation hands the frames and the haptic loops: aspirated tissue leaves the
// frames (the CPU solver's pair mask changed), each step's tool forces go to the loops.
ViewerSimulation::Hooks Viewer::hooks() {
  ViewerSimulation::Hooks hooks;
  if (!tools_.haptics.empty()) hooks.tool_pose = tools_.haptics.pose_source();
  hooks.on_tool_step = [this](double t, const std::vector<ToolStepRecord>& records) {
    if (!tools_.haptics.empty()) tools_.haptics.publish(t, records);
  };
  hooks.on_aspiration = [this](const AspirationEvent& e) {
    writer_.apply_aspiration(e);
    solver_.alive_at = std::numeric_limits<size_t>::max();
  };
  return hooks;
}

void Viewer::run() {
  start();
  auto stopping = [this] { return options_.stop_requested && options_.stop_requested(); };
  while (glfwWindowShouldClose(window_.window) != GLFW_TRUE && !stopping()) {
    glfwPollEvents();
    if (controls_.take_stereo_toggle()) {
      mode_ = mode_ == RenderSettings::Mode::Stereo ? RenderSettings::Mode::Mono
                                                    : RenderSettings::Mode::Stereo;
    }
    advance(steps_for_frame());
    if (!draw()) {
      glfwWaitEventsTimeout(0.1);  // minimised: wake up to poll stop_requested
      continue;
    }
    update_title();
  }
}

// The haptic loops, the controls' callbacks and what the viewer shows where.
void Viewer::start() {
  tools_.haptics.start();
  controls_.set_haptic_tools(tools_.targets);
  GLFWwindow* window = window_.window;
  glfwSetWindowUserPointer(window, &controls_);
  glfwSetKeyCallback(window, on_key);
  glfwSetMouseButtonCallback(window, on_button);
  glfwSetCursorPosCallback(window, on_cursor);
  glfwSetScrollCallback(window, on_scroll);
  std::printf(
      "phyxel view: %s, %zu phyxels, simulating on %s, rendering on %s, showing on %s\n"
      "  drag: orbit, wheel: zoom, space: pause, n: one step, s: mono/stereo, p: picture, q: quit\n"
      "%s",
      file_.c_str(), set_.size(), solver_.solver().device().c_str(), ctx_.info().name.c_str(),
      presenter_.device_name().c_str(),
      tools_.targets.empty() ? ""
                             : "  haptic tools: right drag (or shift + drag): move in the view "
                               "plane, shift + wheel: push along the view\n");
  std::fflush(stdout);
}

// The steps this frame advances: what the wall clock owes, n's single steps while paused.
int64_t Viewer::steps_for_frame() {
  const int64_t due = pacer_.steps_due(wall(), !controls_.paused() && sim_.halted().empty());
  int64_t advance = controls_.paused() ? controls_.steps_for_frame(1) : due;
  if (!controls_.paused()) controls_.steps_for_frame(1);  // consumes a stray n
  // Keys and the window are handled between advances: on a slow device (lavapipe), advance no
  // more than about kMaxAdvanceSeconds of wall time per frame at the rate measured so far (one
  // step until it is measured), so the viewer answers within a fraction of a second however
  // far behind it is.
  constexpr double kMaxAdvanceSeconds = 0.2;
  if (seconds_per_step_ <= 0) return std::min<int64_t>(advance, 1);  // measures the rate
  return std::min<int64_t>(
      advance, std::max<int64_t>(1, static_cast<int64_t>(kMaxAdvanceSeconds / seconds_per_step_)));
}

void Viewer::advance(int64_t steps) {
  if (steps <= 0 || !sim_.halted().empty()) return;
  const double advance_start = wall();
  const int64_t from = sim_.step();
  sim_.advance(steps);
  const int64_t done = sim_.step() - from;
  if (done <= 0) return;
  seconds_per_step_ = (wall() - advance_start) / double(done);
  pacer_.advanced(done);
}

// The frame of the state now, shown; false while the window is minimised.
bool Viewer::draw() {
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(window_.window, &fw, &fh);
  if (fw <= 0 || fh <= 0) return false;
  RenderSettings r = scene_.render;
  const bool side_by_side = mode_ == RenderSettings::Mode::Stereo &&
                            r.stereo.layout == StereoSettings::Layout::SideBySide;
  r.width = std::max(1, side_by_side ? fw / 2 : fw);
  r.height = fh;
  int ww = 0, wh = 0;  // the cursor's units (differ from the framebuffer's on HiDPI)
  glfwGetWindowSize(window_.window, &ww, &wh);
  controls_.set_view_size(side_by_side ? ww / 2.0 : ww, wh);
  for (const size_t k : controls_.take_moved_tools()) {
    const HapticTarget& h = controls_.haptic_tools()[k];
    tools_.drag(h.tool, h.pose);
  }
  writer_.set_setup(make_frame_setup(controls_.orbit().camera(writer_.camera()), r, mode_));
  const double t = double(sim_.step()) * step_time();
  if (!scene_.tools.empty()) {
    writer_.set_tools(viewer_tools(
        scene_.tools, t, controls_.haptic_tools(),
        [this](size_t tool, const ToolPose& target) { return tools_.pose(tool, target); }));
  }
  // Cuts since the last frame: cut-face surfels; the GPU solver's buffers carry its pair
  // weights, the CPU solver's alive mask is uploaded when its severed count changed.
  writer_.follow_cuts(solver_.solver(), false);
  // The video texture: the newest frame decoded by now (never waits for the decoder).
  writer_.advance_video(t, false);
  const RgbaImage frame = solver_.render(writer_);
  presenter_.present(frame);
  if (controls_.take_screenshot()) save_picture(options_.picture_dir, sim_.step(), frame);
  ++frames_;
  return true;
}

// Twice a second: the step, pause, mode, frame rate and real-time factor, why the simulation
// halted or what each tool feels and the pairs cut.
void Viewer::update_title() {
  const auto now = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(now - last_title_).count();
  if (seconds <= 0.5) return;
  const std::string& halted = sim_.halted();
  const double real_time = pacer_.factor();
  std::string note = halted;
  const std::vector<ToolStepRecord>& felt = sim_.felt();
  const std::vector<double> lagging = tools_.lagging_since_last();
  for (size_t t = 0; t < felt.size() && halted.empty(); ++t)
    note += (note.empty() ? "" : ", ") +
            tool_note(scene_.tools[t].name, felt[t].force.norm(), felt[t].contacts, lagging[t]);
  if (const size_t cut = severed_pair_count(solver_.solver()); cut > 0 && halted.empty())
    note += (note.empty() ? "" : ", ") + std::to_string(cut) + " pairs cut";
  glfwSetWindowTitle(
      window_.window,
      viewer_title(file_, sim_.step(), controls_.paused(), mode_ == RenderSettings::Mode::Stereo,
                   frames_ / seconds, note, controls_.paused() ? -1 : real_time)
          .c_str());
  frames_ = 0;
  last_title_ = now;
}

}  // namespace

bool viewer_available() {
  return true;
}

void run_viewer(const Scene& scene, const ViewerOptions& options) {
  Viewer(scene, options).run();
}

}  // namespace phyxel::render
