#include "render/viewer_controls.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <utility>

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
    case ViewerKey::P:
      screenshot_ = true;
      break;
    case ViewerKey::Q:
    case ViewerKey::Escape:
      quit_ = true;
      break;
    case ViewerKey::Other:
      break;
  }
}

Eigen::Vector2d view_pixel(const Camera& camera, double eye_width, double height,
                           const Vec3& point) {
  return project_to_pixel(mono_eye(camera, eye_width / height), point, eye_width, height).head<2>();
}

Vec3 drag_in_view_plane(const Camera& camera, double height, const Vec3& point, double dx,
                        double dy) {
  const double depth = (point - camera.position).dot(camera.forward());
  const double per_pixel =
      2 * depth * std::tan(0.5 * camera.fov_y_deg * std::numbers::pi / 180) / height;
  return per_pixel * (dx * camera.right() - dy * camera.true_up());
}

Vec3 push_along_view(const Camera& camera, const Vec3& point, double fraction) {
  return point + fraction * (point - camera.position);
}

std::vector<HapticTarget> haptic_targets(const std::vector<ToolDesc>& tools) {
  std::vector<HapticTarget> out;
  for (size_t k = 0; k < tools.size(); ++k)
    if (tools[k].control == ToolDesc::Control::Haptic)
      out.push_back({k, pose_at(tools[k].path, tools[k].path.empty() ? 0.0 : tools[k].path[0].t)});
  return out;
}

std::vector<ToolDrawable> viewer_tools(
    const std::vector<ToolDesc>& tools, double t, const std::vector<HapticTarget>& haptic,
    const std::function<ToolPose(size_t tool, const ToolPose& target)>& haptic_pose) {
  std::vector<ToolDrawable> out = tool_drawables(tools, t);
  for (const HapticTarget& h : haptic)
    if (h.tool < out.size()) out[h.tool].pose = haptic_pose ? haptic_pose(h.tool, h.pose) : h.pose;
  return out;
}

void ViewerControls::set_haptic_tools(std::vector<HapticTarget> tools) {
  tools_ = std::move(tools);
  moved_.clear();
  active_tool_ = 0;
  if (drag_ == Drag::Tool) drag_ = Drag::None;
}

void ViewerControls::set_view_size(double eye_width, double height) {
  eye_width_ = std::max(eye_width, 1.0);
  height_ = std::max(height, 1.0);
}

std::vector<size_t> ViewerControls::take_moved_tools() {
  std::vector<size_t> moved;
  moved.swap(moved_);
  return moved;
}

void ViewerControls::mark_moved(size_t k) {
  active_tool_ = k;
  if (std::find(moved_.begin(), moved_.end(), k) == moved_.end()) moved_.push_back(k);
}

void ViewerControls::button(ViewerButton b, bool pressed, double x, double y, bool shift) {
  last_x_ = x;
  last_y_ = y;
  if (!pressed) {
    drag_ = Drag::None;
    return;
  }
  const bool tool_drag = b == ViewerButton::Right || shift;
  if (tool_drag && !tools_.empty()) {
    // The tool whose tip shows nearest the cursor (x within its eye when side by side).
    const Camera cam = camera();
    const Eigen::Vector2d at(std::fmod(x, eye_width_), y);
    double best = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < tools_.size(); ++k) {
      const double d = (view_pixel(cam, eye_width_, height_, tools_[k].pose.position) - at).norm();
      if (d < best) best = d, active_tool_ = k;
    }
    drag_ = Drag::Tool;
  } else {
    drag_ = b == ViewerButton::Left ? Drag::Orbit : Drag::None;
  }
}

void ViewerControls::cursor(double x, double y) {
  const double dx = x - last_x_, dy = y - last_y_;
  last_x_ = x;
  last_y_ = y;
  if (drag_ == Drag::Orbit) {
    orbit_.yaw -= kRadiansPerPixel * dx;
    orbit_.pitch = std::clamp(orbit_.pitch + kRadiansPerPixel * dy, -kMaxPitch, kMaxPitch);
  } else if (drag_ == Drag::Tool && active_tool_ < tools_.size()) {
    Vec3& tip = tools_[active_tool_].pose.position;
    tip += drag_in_view_plane(camera(), height_, tip, dx, dy);
    mark_moved(active_tool_);
  }
}

void ViewerControls::scroll(double notches, bool shift) {
  if (shift && active_tool_ < tools_.size()) {
    Vec3& tip = tools_[active_tool_].pose.position;
    tip = push_along_view(camera(), tip, kToolPushPerNotch * notches);
    mark_moved(active_tool_);
    return;
  }
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

bool ViewerControls::take_screenshot() {
  const bool take = screenshot_;
  screenshot_ = false;
  return take;
}

std::string tool_note(const std::string& name, double force, uint32_t contacts, double lagging_at) {
  char text[192], lag[96] = "";
  if (lagging_at > 0)
    std::snprintf(lag, sizeof lag, ", lagging the hand at its top speed %.3g m/s", lagging_at);
  std::snprintf(text, sizeof text, "%s %.3f N (%u contacts%s)", name.c_str(), force, contacts, lag);
  return text;
}

std::string viewer_title(const std::string& file, int64_t step, bool paused, bool stereo,
                         double fps, const std::string& note, double real_time) {
  char title[512], factor[64] = "";
  if (real_time >= 0)
    std::snprintf(factor, sizeof factor, "  %.2fx real time%s", real_time,
                  real_time < 0.95 ? " (behind)" : "");
  std::snprintf(title, sizeof title, "phyxel view %s  step %lld%s  %s  %.1f fps%s%s%s",
                file.c_str(), static_cast<long long>(step), paused ? " (paused)" : "",
                stereo ? "stereo" : "mono", fps, factor, note.empty() ? "" : "  ", note.c_str());
  return title;
}

}  // namespace phyxel::render
