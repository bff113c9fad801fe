#include "render/viewer_controls.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace phyxel::render {

Orbit::Orbit(const Camera& c) : target(c.target), up(c.up.normalized()) {
  const Vec3 back = c.position - c.target;
  distance = back.norm();
  Vec3 flat = back - back.dot(up) * up;
  if (!(flat.norm() > 1e-12 * distance)) {  // looking along up: any horizontal direction
    flat = c.true_up().cross(up);
    if (!flat.allFinite() || !(flat.norm() > 1e-12)) flat = up.unitOrthogonal();
  }
  front = flat.normalized();
  side = up.cross(front);
  pitch = std::asin(std::clamp(back.normalized().dot(up), -1.0, 1.0));
}

Vec3 Orbit::position() const {
  const Vec3 dir =
      std::cos(pitch) * (std::cos(yaw) * front + std::sin(yaw) * side) + std::sin(pitch) * up;
  return target + distance * dir;
}

Camera Orbit::camera(const Camera& base) const {
  Camera c = base;
  c.position = position();
  c.target = target;
  return c;
}

void ViewerControls::key(ViewerKey k) {
  switch (k) {
    case ViewerKey::Space:
      paused_ = !paused_;
      break;
    case ViewerKey::N:
      step_once_ = paused_;
      break;
    case ViewerKey::S:
      toggle_stereo_ = !toggle_stereo_;
      break;
    case ViewerKey::Q:
    case ViewerKey::Escape:
      quit_ = true;
      break;
    case ViewerKey::Other:
      break;
  }
}

void ViewerControls::button(bool pressed, double x, double y) {
  dragging_ = pressed;
  last_x_ = x;
  last_y_ = y;
}

void ViewerControls::cursor(double x, double y) {
  if (!dragging_) return;
  orbit_.yaw -= kRadiansPerPixel * (x - last_x_);
  orbit_.pitch = std::clamp(orbit_.pitch + kRadiansPerPixel * (y - last_y_), -kMaxPitch, kMaxPitch);
  last_x_ = x;
  last_y_ = y;
}

void ViewerControls::scroll(double notches) {
  orbit_.distance *= std::pow(kZoomPerNotch, notches);
}

int64_t ViewerControls::steps_for_frame(int64_t every) {
  const int64_t steps = paused_ ? (step_once_ ? 1 : 0) : every;
  step_once_ = false;
  return steps;
}

bool ViewerControls::take_stereo_toggle() {
  const bool toggle = toggle_stereo_;
  toggle_stereo_ = false;
  return toggle;
}

std::string viewer_title(const std::string& file, int64_t step, bool paused, bool stereo,
                         double fps, const std::string& note) {
  char title[512];
  std::snprintf(title, sizeof title, "phyxel view %s  step %lld%s  %s  %.1f fps%s%s", file.c_str(),
                static_cast<long long>(step), paused ? " (paused)" : "", stereo ? "stereo" : "mono",
                fps, note.empty() ? "" : "  ", note.c_str());
  return title;
}

}  // namespace phyxel::render
