// What the window viewer's mouse and keys do, without GLFW (render/viewer_glfw.cpp forwards
// its callbacks here), so that the controls are tested on machines without a display:
//
//   left drag          orbit the camera around its target (yaw about `up`, pitch towards it,
//                      pitch held within +-1.5 rad so the view never flips)
//   wheel              move towards (up) or away from (down) the target, x 0.9 per notch
//   space              pause / resume the simulation
//   n                  one simulation step, while paused
//   s                  mono <-> stereo
//   escape, q          quit
//
// Haptic tools (scene tools with "control": "haptic", set_haptic_tools), when there are some:
//
//   right drag, or shift + left drag
//                      move the tool whose tip is nearest the cursor at the press in the
//                      camera's view plane through its tip: the tip follows the cursor
//                      (drag_in_view_plane), its axis does not turn
//   shift + wheel      push the last moved tool (at first the first one) along the view ray
//                      through its tip: away from the camera (wheel up) or towards it (down),
//                      kToolPushPerNotch of the tip's distance per notch (push_along_view)
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "engine/scene/tool_desc.h"
#include "render/camera.h"
#include "render/tool_raycast.h"

namespace phyxel::render {

// Where `point` shows in a view of eye_width x height window pixels of `camera` (the mono
// eye; stereo eyes differ only by their parallax): x right, y down from the top left.
Eigen::Vector2d view_pixel(const Camera& camera, double eye_width, double height,
                           const Vec3& point);

// How far `point` must move for its image to follow the cursor by (dx, dy) window pixels
// (y down) in a view `height` pixels high: along the camera's right and true up, in the plane
// through `point` perpendicular to the view direction, each pixel 2 z tan(fov_y / 2) / height
// at the point's depth z along the camera's forward axis (exact for the mono eye and for both
// stereo eyes, whose frusta differ by a shift only).
Vec3 drag_in_view_plane(const Camera& camera, double height, const Vec3& point, double dx,
                        double dy);

// `point` moved along the ray from the camera's position through it, by `fraction` of its
// distance from the camera (positive: away); its image does not move.
Vec3 push_along_view(const Camera& camera, const Vec3& point, double fraction);

// A camera orbiting its target. Constructed from a camera, position() gives back its position.
struct Orbit {
  Vec3 target, up, front, side;
  double yaw = 0, pitch = 0, distance = 1;

  explicit Orbit(const Camera& c);
  Vec3 position() const;
  // `base` looking from position() at the target.
  Camera camera(const Camera& base) const;
};

enum class ViewerKey { Space, N, S, P, Q, Escape, Other };
enum class ViewerButton { Left, Right };

// A haptic tool under the mouse: its index in the scene's tools and its target pose.
struct HapticTarget {
  size_t tool = 0;
  ToolPose pose;
};

// The scene's haptic tools ("control": "haptic"), each at the first key of its path.
std::vector<HapticTarget> haptic_targets(const std::vector<ToolDesc>& tools);

// What the viewer draws at simulated time t: path tools at pose_at(path, t), haptic tools at
// haptic_pose(tool, target) when given, else at their target.
std::vector<ToolDrawable> viewer_tools(
    const std::vector<ToolDesc>& tools, double t, const std::vector<HapticTarget>& haptic,
    const std::function<ToolPose(size_t tool, const ToolPose& target)>& haptic_pose = {});

class ViewerControls {
 public:
  static constexpr double kRadiansPerPixel = 0.008;
  static constexpr double kMaxPitch = 1.5;
  static constexpr double kZoomPerNotch = 0.9;
  static constexpr double kToolPushPerNotch = 0.02;

  // `camera` is also the base of the orbit's cameras (field of view) for the tool mapping.
  explicit ViewerControls(const Camera& camera) : orbit_(camera), base_(camera) {}

  void key(ViewerKey k);
  void button(bool pressed, double x, double y) {  // the left mouse button, no modifier
    button(ViewerButton::Left, pressed, x, y, false);
  }
  void button(ViewerButton b, bool pressed, double x, double y, bool shift);
  void cursor(double x, double y);
  // The cursor as the events so far left it (a button press is taken where the events put
  // the cursor, not where the pointer is by the time it is processed).
  Eigen::Vector2d cursor_position() const { return {last_x_, last_y_}; }
  void scroll(double notches, bool shift = false);

  // The haptic tools and their starting targets; the window's size per eye in the cursor's
  // units (side by side: half the window's width), for picking and the drag's scale.
  void set_haptic_tools(std::vector<HapticTarget> tools);
  void set_view_size(double eye_width, double height);
  const std::vector<HapticTarget>& haptic_tools() const { return tools_; }
  // Indices into haptic_tools() of the tools moved since the last call (each once, in order).
  std::vector<size_t> take_moved_tools();
  // The camera the mouse maps through: the orbit's view of the base camera.
  Camera camera() const { return orbit_.camera(base_); }

  // Steps to advance for this frame: `every` while running, 1 after n while paused, else 0.
  int64_t steps_for_frame(int64_t every);
  // Whether s was pressed since the last call.
  bool take_stereo_toggle();
  // Whether p (save the view as a PNG) was pressed since the last call.
  bool take_screenshot();

  const Orbit& orbit() const { return orbit_; }
  bool paused() const { return paused_; }
  bool quit() const { return quit_; }

 private:
  enum class Drag { None, Orbit, Tool };
  void mark_moved(size_t k);

  Orbit orbit_;
  Camera base_;
  bool paused_ = false, quit_ = false, step_once_ = false, toggle_stereo_ = false,
       screenshot_ = false;
  Drag drag_ = Drag::None;
  double last_x_ = 0, last_y_ = 0;
  std::vector<HapticTarget> tools_;
  std::vector<size_t> moved_;
  size_t active_tool_ = 0;  // dragged or pushed last
  double eye_width_ = 1, height_ = 1;
};

// The window title: scene, step, pause state, render mode, frame rate, a note (empty, or why
// the simulation was halted) and, when not negative, the real-time factor (simulated seconds
// per wall second).
std::string viewer_title(const std::string& file, int64_t step, bool paused, bool stereo,
                         double fps, const std::string& note = {}, double real_time = -1);

// A tool's part of the title's note: what it feels, and, where its haptic loop held it to its
// top speed since the last title (lagging_at, m/s; 0: it did not), that it lags its device.
std::string tool_note(const std::string& name, double force, uint32_t contacts,
                      double lagging_at = 0);

}  // namespace phyxel::render
