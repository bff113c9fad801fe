// Tools as a scene describes them (DESIGN.md section 8): shape, path or haptic control, and
// the action of each instrument (blade, suction, grasp). Plain data; the pose and distance math
// is in engine/geometry/tool.h.
#pragma once

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "engine/geometry/tool.h"

namespace phyxel {

// The resistance of the pairs a blade with a threshold has crossed, per unit area of the cut
// plane and metre the edge has passed them (docs/cutting.md, "The edge's resistance").
inline constexpr double kDefaultEdgeStiffness = 1e7;

// The cutting part of a tool (ToolDesc::blade, ContactTool::blade; engine/solver/cutting.h).
struct Blade {
  double length = 0;                         // m, from the tip along the axis (> 0: the tool cuts)
  Vec3 edge = Vec3::UnitX();                 // unit, perpendicular to the axis at the first key
  Vec3 reference_axis = Vec3::UnitZ();       // the axis at the path's first key
  double threshold = 0;                      // N: the edge force at which the tissue separates
  double reach = 0;                          // m: how far ahead of the edge it separates
  double stiffness = kDefaultEdgeStiffness;  // N/m^3: the edge's resistance (docs/cutting.md)
  bool cuts() const { return length > 0; }
};

// The action of an aspirator (ToolDesc::suction, ContactTool::suction; engine/solver/suction.h):
// while on, its mouth (the tip) pulls the phyxels within `reach` ahead of it toward itself,
// `pressure` times the mouth's area (pi radius^2) in all when the reach is full of tissue.
struct Suction {
  double pressure = 0;      // Pa (> 0: the tool sucks)
  double reach = 0;         // m, from the tip
  double flow_speed = 0.5;  // m/s: the speed toward the mouth at which the pull vanishes
  // s: the longest time between two aspirations (docs/suction.md, "Resolution"): a fixed
  // time, not a number of substeps, so that refining the tissue does not change it.
  double interval = 0.003;
  double from = 0;  // s: on during [from, until)
  double until = std::numeric_limits<double>::infinity();
  bool sucks() const { return pressure > 0; }
  bool on_at(double t) const { return sucks() && from <= t && t < until; }
};

// The action of a grasper (ToolDesc::grasp, ContactTool::grasp; engine/solver/grasper.h): its
// jaws close at `from` on every phyxel within `reach` of its tip and carry them rigidly with
// the tool until `until`, when they let go.
struct Grasp {
  double reach = 0;  // m, from the tip (> 0: the tool grasps)
  double from = 0;   // s: closed during [from, until)
  double until = std::numeric_limits<double>::infinity();
  bool grasps() const { return reach > 0; }
  bool closed_at(double t) const { return grasps() && from <= t && t < until; }
};

// Virtual coupling between a haptic device and the simulated tool (engine/surgery/haptic_loop.h).
struct CouplingSettings {
  double stiffness = 200;  // N/m, spring between the device pose and the simulated tool
  double damping = 0;      // N s/m; 0: critical for `mass`
  double mass = 0.02;      // kg, the simulated tool's mass in the haptic loop
  double max_force = 8;    // N, the force sent to the hand is clamped to this
  // m/s in simulated time, the simulated tool's top speed; 0: the scene's (live_tool_speed).
  double max_speed = 0;
};

struct ToolDesc {
  enum class Type { Probe, Scalpel, Suction, Grasper };
  enum class Control { Path, Haptic };
  std::string name;
  Type type = Type::Probe;
  ToolShape shape;
  std::vector<ToolKey> path;  // strictly increasing t; at least one key
  double friction = 0;        // Coulomb coefficient mu (>= 0)
  Control control = Control::Path;
  CouplingSettings coupling;  // control haptic only
  Blade blade;                // scalpel only (engine/solver/cutting.h)
  Suction suction;            // suction only (engine/solver/suction.h)
  Grasp grasp;                // grasper only (engine/solver/grasper.h)
  // A scripted cycle: the path and the suction and grasp windows repeat every `repeat` s (0:
  // once); the tool at t does what it did at t mod repeat (the path ends where it began).
  double repeat = 0;
  double cycle_time(double t) const { return repeat > 0 ? std::fmod(t, repeat) : t; }
  // Added to the path at each new cycle ("repeat_shift", m): in cycle k = floor(t / repeat)
  // the tool follows its path moved by k * repeat_shift (fresh tissue every cycle).
  Vec3 repeat_shift = Vec3::Zero();
  double cycle_index(double t) const {
    return repeat > 0 ? std::round((t - std::fmod(t, repeat)) / repeat) : 0.0;
  }
  // The scripted pose at simulated time t: the path at t's cycle time, shifted by its cycle.
  ToolPose path_pose(double t) const {
    ToolPose p = pose_at(path, cycle_time(t));
    p.position += cycle_index(t) * repeat_shift;
    return p;
  }
};

}  // namespace phyxel
