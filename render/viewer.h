// `phyxel view`: a scene simulated live in a window (GLFW + a Vulkan swapchain), with the
// same splat passes, mono or stereo (side by side or anaglyph) as the scene's `render` says.
// Mouse and keys: render/viewer_controls.h (drag: orbit, wheel: zoom, space: pause, n: one
// step while paused, s: mono/stereo, p: save the view as a PNG, q or escape: quit; right drag or
// shift + left drag: move the haptic tool nearest the cursor in the view plane, shift + wheel: push
// it along the view). The title shows the step, the pause state, the mode and the frame rate.
//
// Tools: every tool of the scene is drawn (steel, render/tool_raycast.h). A path-controlled
// tool is drawn at pose_at(path, simulated time), the time being steps x simulation.dt. A
// tool with "control": "haptic" follows the mouse: its target pose starts at the first key of
// its path and moves with the drags and the wheel; ViewerOptions::on_tool_drag hands it out
// (to the haptic loop and the physics) and ViewerOptions::haptic_pose says where to draw it.
//
// The simulation is `phyxel run`'s run loop (render/viewer_simulation.h): the same steps, loads,
// sleep, tearing and aspiration. One that turns non-finite or runs away (a phyxel faster than its
// material's wave speed, at the loop's checks) is halted, and the title and standard error say
// at which step and phyxel.
//
// Built with PHYXEL_WITH_WINDOW (on by default); otherwise run_viewer says so in one line.
#pragma once

#include <cstddef>
#include <functional>
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
  // Where p saves the view: picture_dir/view-STEP.png (view-STEP-K.png when that exists),
  // created when missing; the file is named on standard output.
  std::string picture_dir = ".";

  // Haptic tools. Both run on the viewer's thread, between frames; `tool` is the index in
  // scene.tools, the poses are in world coordinates (m), the axis a unit vector.
  // on_tool_drag(tool, target): the mouse moved the tool's target pose (its tip; the axis is
  // that of the path's first key). Called once per haptic tool with its starting pose before
  // the first frame, then after every drag or shift + wheel that moved it.
  std::function<void(size_t tool, const ToolPose& target)> on_tool_drag;
  // haptic_pose(tool, target): where to draw the tool (e.g. the simulated tool of the virtual
  // coupling, which lags its target); unset: at the target.
  std::function<ToolPose(size_t tool, const ToolPose& target)> haptic_pose;
  // Polled every frame (and at least every 0.1 s while the window is minimised): true closes
  // the viewer as closing its window does (phyxel view: SIGINT, SIGTERM).
  std::function<bool()> stop_requested;
};

// Whether this build has the window viewer.
bool viewer_available();

// Opens the window and runs until it is closed or options.stop_requested says stop. Throws
// std::runtime_error with one line when there is no display or no window support, SceneError for
// bad scene input.
void run_viewer(const Scene& scene, const ViewerOptions& options);

}  // namespace phyxel::render
