#include "render/real_time_pacer.h"

#include <algorithm>
#include <cmath>

namespace phyxel::render {

RealTimePacer::RealTimePacer(double step_time, int64_t cap)
    : dt_(step_time), cap_(std::max<int64_t>(cap, 1)) {}

int64_t RealTimePacer::steps_due(double now, bool running) {
  const double elapsed = started_ ? std::max(0.0, now - last_now_) : 0.0;
  started_ = true;
  last_now_ = now;
  behind_ = false;
  if (!running) return 0;
  owed_wall_ += elapsed;
  running_wall_ += elapsed;
  const double owed = owed_wall_ - simulated_;
  auto due = static_cast<int64_t>(std::floor(owed / dt_ + 1e-9));
  if (due > cap_) {
    due = cap_;
    owed_wall_ = simulated_ + double(cap_) * dt_;  // drop the debt beyond this frame
    behind_ = true;
  }
  return std::max<int64_t>(due, 0);
}

void RealTimePacer::advanced(int64_t steps) {
  simulated_ += double(steps) * dt_;
}

double RealTimePacer::factor() {
  const double wall = running_wall_ - window_wall_;
  const double sim = simulated_ - window_simulated_;
  window_wall_ = running_wall_;
  window_simulated_ = simulated_;
  return wall > 0 ? sim / wall : 0.0;
}

}  // namespace phyxel::render
