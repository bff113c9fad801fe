// The window viewer (PHYXEL_WITH_WINDOW): the CPU reference solver advanced live, frames from
// the splat renderer (headless context, as `phyxel run --render`) shown through Presenter.
#include <GLFW/glfw3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "engine/simulation.h"
#include "render/frame_output.h"
#include "render/present_glfw.h"
#include "render/viewer.h"

namespace phyxel::render {
namespace {

constexpr const char* kHeadless =
    "for frames without a display use: phyxel run SCENE --render mono|stereo --out DIR";

// Camera orbiting its target: yaw about `up`, pitch towards it, distance.
struct Orbit {
  Vec3 target, up, front, side;
  double yaw = 0, pitch = 0, distance = 1;

  explicit Orbit(const Camera& c) : target(c.target), up(c.up.normalized()) {
    const Vec3 back = c.position - c.target;
    distance = back.norm();
    const Vec3 flat = back - back.dot(up) * up;
    front = flat.norm() > 1e-12 * distance ? Vec3(flat.normalized()) : Vec3(c.true_up().cross(up));
    side = up.cross(front);
    pitch = std::asin(std::clamp(back.normalized().dot(up), -1.0, 1.0));
  }
  Vec3 position() const {
    const Vec3 dir =
        std::cos(pitch) * (std::cos(yaw) * front + std::sin(yaw) * side) + std::sin(pitch) * up;
    return target + distance * dir;
  }
};

struct Input {
  Orbit* orbit = nullptr;
  bool dragging = false, paused = false, step_once = false, toggle_stereo = false;
  double last_x = 0, last_y = 0;
};

Input& input_of(GLFWwindow* w) {
  return *static_cast<Input*>(glfwGetWindowUserPointer(w));
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action != GLFW_PRESS) return;
  Input& in = input_of(w);
  if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(w, GLFW_TRUE);
  if (key == GLFW_KEY_SPACE) in.paused = !in.paused;
  if (key == GLFW_KEY_N) in.step_once = true;
  if (key == GLFW_KEY_S) in.toggle_stereo = true;
}

void on_button(GLFWwindow* w, int button, int action, int) {
  Input& in = input_of(w);
  if (button != GLFW_MOUSE_BUTTON_LEFT) return;
  in.dragging = action == GLFW_PRESS;
  glfwGetCursorPos(w, &in.last_x, &in.last_y);
}

void on_cursor(GLFWwindow* w, double x, double y) {
  Input& in = input_of(w);
  if (!in.dragging) return;
  in.orbit->yaw -= 0.008 * (x - in.last_x);
  in.orbit->pitch = std::clamp(in.orbit->pitch + 0.008 * (y - in.last_y), -1.5, 1.5);
  in.last_x = x;
  in.last_y = y;
}

void on_scroll(GLFWwindow* w, double, double dy) {
  input_of(w).orbit->distance *= std::pow(0.9, dy);
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
  auto solver = make_cpu_solver(set, scene.simulation.gravity, options.threads);
  const TimeStepPlan plan = plan_time_step(scene, set);
  gpu::ContextOptions context;
  context.device = options.render_device;
  context.validation = options.validation;
  gpu::Context ctx(context);
  FrameWriter writer(scene, set, {mode, {}, options.render_device}, &ctx);
  HostInputs inputs(ctx, set, solver->neighbours());

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
  Orbit orbit(writer.camera());
  Input input;
  input.orbit = &orbit;
  glfwSetWindowUserPointer(window, &input);
  glfwSetKeyCallback(window, on_key);
  glfwSetMouseButtonCallback(window, on_button);
  glfwSetCursorPosCallback(window, on_cursor);
  glfwSetScrollCallback(window, on_scroll);
  std::printf(
      "phyxel view: %s, %zu phyxels, rendering on %s, showing on %s\n"
      "  drag: orbit, wheel: zoom, space: pause, n: one step, s: mono/stereo, q: quit\n",
      file.c_str(), set.size(), ctx.info().name.c_str(), presenter.device_name().c_str());
  std::fflush(stdout);

  int64_t step = 0;
  auto last_title = std::chrono::steady_clock::now();
  int frames = 0;
  while (glfwWindowShouldClose(window) != GLFW_TRUE) {
    glfwPollEvents();
    if (input.toggle_stereo) {
      mode = mode == RenderSettings::Mode::Stereo ? RenderSettings::Mode::Mono
                                                  : RenderSettings::Mode::Stereo;
      input.toggle_stereo = false;
    }
    int64_t advance = input.paused ? 0 : scene.render.every;
    if (input.step_once) advance = 1;
    input.step_once = false;
    if (advance > 0) {
      solver->advance(advance * plan.substeps, plan.dt_used);
      step += advance;
    }
    int fw = 0, fh = 0;
    glfwGetFramebufferSize(window, &fw, &fh);
    if (fw <= 0 || fh <= 0) {
      glfwWaitEvents();
      continue;
    }
    RenderSettings r = scene.render;
    const bool side_by_side = mode == RenderSettings::Mode::Stereo &&
                              r.stereo.layout == StereoSettings::Layout::SideBySide;
    r.width = std::max(1, side_by_side ? fw / 2 : fw);
    r.height = fh;
    Camera camera = writer.camera();
    camera.position = orbit.position();
    camera.target = orbit.target;
    writer.set_setup(make_frame_setup(camera, r, mode));
    inputs.set_displacement(solver->read_state(false).displacement);
    presenter.present(writer.render(inputs.inputs()));
    ++frames;
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_title).count();
    if (seconds > 0.5) {
      char title[256];
      std::snprintf(title, sizeof title, "phyxel view %s  step %lld%s  %.1f fps", file.c_str(),
                    static_cast<long long>(step), input.paused ? " (paused)" : "",
                    frames / seconds);
      glfwSetWindowTitle(window, title);
      frames = 0;
      last_title = now;
    }
  }
}

}  // namespace phyxel::render
