// Paces a live simulation to the wall clock (DESIGN.md section 8, "Real time"): how many steps
// a frame advances so that simulated time keeps up with the wall time spent running (paused
// time does not count), at most `cap` per frame so frames keep coming. When the simulation
// cannot keep up, the debt beyond one frame's cap is dropped instead of piling up, and
// factor() reports how fast it really ran (the viewer's title says so).
#pragma once

#include <cstdint>

namespace phyxel::render {

class RealTimePacer {
 public:
  RealTimePacer(double step_time, int64_t cap);
  // Steps due now (wall time `now`, s); `running`: not paused (paused time is not owed).
  int64_t steps_due(double now, bool running);
  // The steps the frame advanced (due or not: a single step while paused counts too).
  void advanced(int64_t steps);
  // Simulated seconds per running wall second since the last call (0 before any running time).
  double factor();
  bool behind() const { return behind_; }  // the last steps_due dropped debt

 private:
  double dt_;
  int64_t cap_;
  bool started_ = false, behind_ = false;
  double last_now_ = 0;
  double owed_wall_ = 0;     // running wall time the simulation owes (debt dropped)
  double running_wall_ = 0;  // running wall time, for factor()
  double simulated_ = 0;     // simulated time advanced while running
  double window_wall_ = 0, window_simulated_ = 0;
};

}  // namespace phyxel::render
