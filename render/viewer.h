// `phyxel view`: a scene simulated live in a window (GLFW + a Vulkan swapchain), with the
// same splat passes, mono or stereo (side by side or anaglyph) as the scene's `render` says.
// Mouse and keys: render/viewer_controls.h (drag: orbit, wheel: zoom, space: pause, n: one
// step while paused, s: mono/stereo, q or escape: quit). The title shows the step, the pause
// state, the mode and the frame rate. A simulation that turns non-finite or runs away (a
// phyxel faster than its material's wave speed; checked twice a second) is halted, and the
// title and standard error say at which step and phyxel.
//
// Built with PHYXEL_WITH_WINDOW (on by default); otherwise run_viewer says so in one line.
#pragma once

#include <optional>
#include <string>

#include "engine/scene/scene.h"

namespace phyxel::render {

struct ViewerOptions {
  // Solver: "cpu" (the reference) or a Vulkan device spec (device_info.h) for the GPU solver,
  // whose buffers the renderer then reads on the same device (no per-frame copy).
  std::string device = "cpu";
  std::string render_device = "gpu";         // Vulkan device of the renderer with device "cpu"
  int threads = 0;                           // CPU solver threads, 0: all cores
  std::optional<RenderSettings::Mode> mode;  // overrides the scene's render.mode
  bool validation = false;
};

// Whether this build has the window viewer.
bool viewer_available();

// Opens the window and runs until it is closed. Throws std::runtime_error with one line when
// there is no display or no window support, SceneError for bad scene input.
void run_viewer(const Scene& scene, const ViewerOptions& options);

}  // namespace phyxel::render
