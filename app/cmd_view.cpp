// phyxel view SCENE: the scene simulated live in a window (render/viewer.h).
#include <cstdio>
#include <stdexcept>
#include <string>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/options.h"
#include "compute/vk_check.h"
#include "render/viewer.h"

namespace phyxel::app {
namespace {

constexpr const char* kViewHelp =
    "usage: phyxel view SCENE [options]\n"
    "\n"
    "Simulates SCENE (CPU reference or GPU solver) and shows it live in a window, drawn by the\n"
    "splat renderer as the scene's render settings say (render.every steps per frame).\n"
    "Needs a display; without one use phyxel run SCENE --render mono|stereo --out DIR.\n"
    "\n"
    "  mouse drag: orbit   wheel: zoom   space: pause   n: one step   s: mono/stereo   q: quit\n"
    "  p: save the view as a PNG (DIR/view-STEP.png, DIR from --out)\n"
    "  tools with \"control\": \"haptic\": right drag (or shift + left drag) moves the one\n"
    "  nearest the cursor in the view plane through its tip; shift + wheel pushes it along\n"
    "  the view (up: away). Path tools move along their paths. A scalpel on the mouse cuts\n"
    "  the way it is dragged; the title counts the pairs cut.\n"
    "\n"
    "options:\n"
    "  --device D          solver: cpu (the double-precision reference, default), gpu (the best\n"
    "                      Vulkan device), gpu:N or part of a device name (the GPU solver, "
    "float32;\n"
    "                      the renderer then reads its buffers on the same device)\n"
    "  --render MODE       mono or stereo (default: the scene's render.mode, mono when none)\n"
    "  --render-device D   Vulkan device of the renderer with --device cpu (default gpu: the "
    "best)\n"
    "  --threads N         CPU solver threads (default: all cores)\n"
    "  --refine K          every object's spacing and support radius divided by K (1 to 16)\n"
    "  --hand TOOL         the scene's tool named TOOL follows the mouse instead of its path\n"
    "                      (as \"control\": \"haptic\"), e.g. the scalpel of\n"
    "                      scenes/breast_resection.json\n"
    "  --validate          Vulkan validation layers on for the renderer\n"
    "  --out DIR           where p saves the view (default: the current directory)\n"
    "  --help              this text\n"
    "\n"
    "SIGINT (Ctrl-C) or SIGTERM closes the viewer as closing its window does; a second signal\n"
    "ends the process at once.\n"
    "\n"
    "exit status: 0 closed, 1 no display or bad input, 2 bad usage, 130 closed by SIGINT,\n"
    "143 closed by SIGTERM";

}  // namespace

int view_command(const Args& args) {
  OptionParser opts("view", args);
  if (opts.flag("--help")) {
    std::puts(kViewHelp);
    return 0;
  }
  render::ViewerOptions options;
  const std::string mode = opts.value("--render", "");
  options.device = opts.value("--device", "cpu");
  options.render_device = opts.value("--render-device", "gpu");
  options.threads = static_cast<int>(opts.integer("--threads", 0, 0, 1024));
  options.validation = opts.flag("--validate");
  options.picture_dir = opts.value("--out", ".");
  const std::string hand = opts.value("--hand", "");
  const double refine = opts.number("--refine", 1, 1, kMaxRefine);
  const std::vector<std::string> positional = opts.finish();
  if (positional.size() != 1) {
    std::fprintf(stderr, "phyxel view: expected one SCENE file (see phyxel view --help)\n");
    return 1;
  }
  if (mode == "mono") {
    options.mode = RenderSettings::Mode::Mono;
  } else if (mode == "stereo") {
    options.mode = RenderSettings::Mode::Stereo;
  } else if (!mode.empty()) {
    std::fprintf(stderr, "phyxel view: --render %s: allowed mono or stereo\n", mode.c_str());
    return 1;
  }
  const InterruptGuard interrupts;  // SIGINT, SIGTERM: close the viewer cleanly
  options.stop_requested = [] { return InterruptGuard::received() != 0; };
  try {
    Scene scene = load_scene(positional[0]);
    refine_scene(scene, refine);
    if (!hand.empty()) {  // the named tool follows the mouse instead of its path
      std::string names;
      ToolDesc* chosen = nullptr;
      for (ToolDesc& t : scene.tools) {
        names += (names.empty() ? "" : ", ") + t.name;
        if (t.name == hand) chosen = &t;
      }
      if (chosen == nullptr) {
        std::fprintf(stderr, "phyxel view: --hand %s: %s has no tool of that name (%s)\n",
                     hand.c_str(), positional[0].c_str(),
                     names.empty() ? "it has no tools" : ("its tools: " + names).c_str());
        return 1;
      }
      chosen->control = ToolDesc::Control::Haptic;
    }
    render::run_viewer(scene, options);
    if (const int signal = InterruptGuard::received(); signal != 0) {
      std::fprintf(stderr, "phyxel view: closed by %s\n", signal_name(signal));
      return interrupted_exit_status(signal);
    }
    return 0;
  } catch (const SceneError& e) {
    std::fprintf(stderr, "%s\n", e.what());
  } catch (const VulkanError& e) {
    std::fprintf(stderr, "phyxel view: %s\n", e.what());
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "%s\n", e.what());
  }
  return 1;
}

}  // namespace phyxel::app
