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
#pragma once

#include <cstdint>
#include <string>

#include "render/camera.h"

namespace phyxel::render {

// A camera orbiting its target. Constructed from a camera, position() gives back its position.
struct Orbit {
  Vec3 target, up, front, side;
  double yaw = 0, pitch = 0, distance = 1;

  explicit Orbit(const Camera& c);
  Vec3 position() const;
  // `base` looking from position() at the target.
  Camera camera(const Camera& base) const;
};

enum class ViewerKey { Space, N, S, Q, Escape, Other };

class ViewerControls {
 public:
  static constexpr double kRadiansPerPixel = 0.008;
  static constexpr double kMaxPitch = 1.5;
  static constexpr double kZoomPerNotch = 0.9;

  explicit ViewerControls(const Camera& camera) : orbit_(camera) {}

  void key(ViewerKey k);
  void button(bool pressed, double x, double y);  // the left mouse button
  void cursor(double x, double y);
  void scroll(double notches);

  // Steps to advance for this frame: `every` while running, 1 after n while paused, else 0.
  int64_t steps_for_frame(int64_t every);
  // Whether s was pressed since the last call.
  bool take_stereo_toggle();

  const Orbit& orbit() const { return orbit_; }
  bool paused() const { return paused_; }
  bool quit() const { return quit_; }

 private:
  Orbit orbit_;
  bool paused_ = false, quit_ = false, step_once_ = false, toggle_stereo_ = false;
  bool dragging_ = false;
  double last_x_ = 0, last_y_ = 0;
};

// The window title: scene, step, pause state, render mode, frame rate and a note (empty, or
// why the simulation was halted).
std::string viewer_title(const std::string& file, int64_t step, bool paused, bool stereo,
                         double fps, const std::string& note = {});

}  // namespace phyxel::render
