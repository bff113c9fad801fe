// RunLoop's checks of a checked step: non-finite values, runaways (a phyxel faster than its
// material's wave speed), rest and sleep.
#include <algorithm>

#include "engine/geometry/tool.h"
#include "engine/run/run_loop.h"
#include "engine/solver/solver.h"

namespace phyxel {

// The checks read reductions: per object its kinetic energy and largest speed where rest or
// sleep is decided, else the largest speed alone. Only a phyxel faster than the slowest wave
// speed (a runaway to name) or an object going to sleep near tools reads u or v back.
bool RunLoop::check() {
  if (!check_finite()) return false;
  std::fill(contacts_since_check_.begin(), contacts_since_check_.end(), 0u);
  std::vector<ObjectMotion> motion;
  double fastest = 0;
  if (scene_.simulation.until_rest.enabled || sleeping_) {
    motion = solver_.object_motion(set_);
    for (const ObjectMotion& m : motion)
      if (!(m.max_speed <= fastest)) fastest = m.max_speed;
  } else {
    fastest = solver_.max_norms().second;
  }
  if (!(fastest <= slowest_wave_) && check_runaway(solver_.read_state(false))) return false;
  decide_rest_and_sleep(motion);
  return true;
}

bool RunLoop::check_stability() {
  if (!check_finite()) return false;
  if (solver_.max_norms().second <= slowest_wave_) return true;
  return !check_runaway(solver_.read_state(false));
}

// No non-finite value (false: the result names the phyxel and the tool most in contact).
bool RunLoop::check_finite() {
  const long bad = solver_.first_non_finite();
  if (bad >= 0) {
    result_.non_finite = true;
    result_.non_finite_step = step_;
    result_.non_finite_phyxel = bad;
    for (size_t k = 0; k < contacts_since_check_.size(); ++k) {
      if (contacts_since_check_[k] > result_.non_finite_tool_contacts) {
        result_.non_finite_tool = static_cast<int>(k);
        result_.non_finite_tool_contacts = contacts_since_check_[k];
      }
    }
    return false;
  }
  return true;
}

// A phyxel faster than its material's wave speed: the run is unstable (true), named with the
// tool nearest it.
bool RunLoop::check_runaway(const PointState& state) {
  const Runaway r = find_runaway(set_, state.velocity);
  if (r.phyxel < 0) return false;
  result_.unstable = true;
  result_.unstable_step = step_;
  result_.unstable_phyxel = r.phyxel;
  result_.unstable_speed = r.speed;
  result_.unstable_wave_speed = r.wave_speed;
  const Vec3 x = set_.rest[r.phyxel] + state.displacement[r.phyxel];
  double near = 0;
  for (const ObjectRange& o : set_.objects)
    if (r.phyxel >= long(o.first) && r.phyxel < long(o.first + o.count))
      near = 2 * o.support_radius;
  for (size_t k = 0; k < tools_.size(); ++k) {
    const double d = tool_distance(tools_.shape(k), tools_.poses()[k], x).distance;
    if (d <= near && (result_.unstable_tool < 0 || d < result_.unstable_tool_distance)) {
      result_.unstable_tool = static_cast<int>(k);
      result_.unstable_tool_distance = d;
    }
  }
  return true;
}

void RunLoop::decide_rest_and_sleep(const std::vector<ObjectMotion>& motion) {
  const UntilRest& rest = scene_.simulation.until_rest;
  const SleepSettings& sleep = scene_.simulation.sleep;
  double kinetic = 0;
  for (const ObjectMotion& m : motion) kinetic += m.kinetic;
  if (rest.enabled) {
    if (kinetic >= rest.kinetic_energy_below) {
      below_since_ = -1;
    } else if (below_since_ < 0) {
      below_since_ = step_;
    }
    if (below_since_ >= 0 && step_ - below_since_ >= rest.for_steps) result_.stopped_at_rest = true;
  }
  std::vector<Vec3> u_now;  // read back once, for the objects that go to sleep now
  for (size_t o = 0; sleeping_ && o < set_.objects.size(); ++o) {
    if (!awake_[o]) continue;
    if (motion[o].kinetic >= sleep.kinetic_energy_below) {
      object_below_since_[o] = -1;
    } else if (object_below_since_[o] < 0) {
      object_below_since_[o] = step_;
    }
    if (object_below_since_[o] >= 0 && step_ - object_below_since_[o] >= sleep.for_steps) {
      awake_[o] = 0;
      if (PassSelection* passes = solver_.pass_selection())
        passes->set_object_awake(static_cast<uint32_t>(o), false);
      ++result_.sleeps;
      if (!tools_.empty()) {  // where it sleeps, for wake_touched_objects
        if (u_now.empty()) u_now = solver_.read_state(false).displacement;
        const ObjectRange& obj = set_.objects[o];
        std::copy(u_now.begin() + obj.first, u_now.begin() + obj.first + obj.count,
                  last_u_.begin() + obj.first);
      }
    }
  }
}

}  // namespace phyxel
