#include "engine/surgery/haptic_loop.h"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace phyxel {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::time_point t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}

// Single-writer maximum of a relaxed atomic.
void raise_to(std::atomic<double>& a, double v) {
  if (v > a.load(std::memory_order_relaxed)) a.store(v, std::memory_order_relaxed);
}

void put(double* w, const Vec3& v) {
  for (int i = 0; i < 3; ++i) w[i] = v[i];
}
Vec3 get(const double* w) {
  return Vec3(w[0], w[1], w[2]);
}

// The most substeps one tick integrates; a longer stall loses the rest of its time.
constexpr int kMaxSubsteps = 64;
// Periods of a stall that are still integrated (the rest is dropped).
constexpr double kMaxCatchUpPeriods = 16;
// The physics' rate (simulated seconds per wall second) is followed over about this many wall
// seconds of snapshots, and never taken below kMinSimRate (a stalled physics).
constexpr double kSimRateSeconds = 0.1;
constexpr double kMinSimRate = 1e-3;

}  // namespace

Vec3 extrapolate_force(double t_prev, const Vec3& f_prev, double t_cur, const Vec3& f_cur,
                       double t) {
  const double period = t_cur - t_prev;
  if (!(period > 0)) return f_cur;
  const double horizon = std::clamp(t - t_cur, 0.0, period);
  return f_cur + (f_cur - f_prev) * (horizon / period);
}

HapticLoop::HapticLoop(std::shared_ptr<HapticDevice> device, const CouplingSettings& coupling,
                       const ToolPose& initial, const HapticLoopSettings& settings)
    : device_(std::move(device)),
      k_(coupling.stiffness),
      b_(coupling.damping),
      m_(coupling.mass),
      max_force_(coupling.max_force),
      max_speed_(coupling.max_speed > 0 ? coupling.max_speed
                                        : std::numeric_limits<double>::infinity()),
      settings_(settings),
      x_t_(initial.position),
      axis_(initial.axis.normalized()) {
  if (!device_) throw std::invalid_argument("haptic loop: no device");
  if (!(k_ > 0) || !std::isfinite(k_)) {
    throw std::invalid_argument("haptic loop: coupling stiffness must be > 0 N/m, got " +
                                std::to_string(k_));
  }
  if (!(m_ > 0) || !std::isfinite(m_)) {
    throw std::invalid_argument("haptic loop: coupling mass must be > 0 kg, got " +
                                std::to_string(m_));
  }
  if (!(b_ >= 0) || !std::isfinite(b_)) {
    throw std::invalid_argument("haptic loop: coupling damping must be >= 0 N s/m, got " +
                                std::to_string(b_));
  }
  if (!(coupling.max_speed >= 0)) {
    throw std::invalid_argument("haptic loop: coupling max_speed must be >= 0 m/s, got " +
                                std::to_string(coupling.max_speed));
  }
  if (!(max_force_ > 0)) {
    throw std::invalid_argument("haptic loop: coupling max_force must be > 0 N, got " +
                                std::to_string(max_force_));
  }
  if (!(settings_.rate_hz > 0) || !std::isfinite(settings_.rate_hz) ||
      !(settings_.velocity_cutoff_hz > 0) || !(settings_.overrun_ms > 0) ||
      !(settings_.spin_us >= 0)) {
    throw std::invalid_argument(
        "haptic loop: rate, velocity cutoff and overrun must be > 0, spin >= 0");
  }
  if (!x_t_.allFinite() || !axis_.allFinite()) {
    throw std::invalid_argument("haptic loop: the initial pose must be finite, axis non-zero");
  }
  if (b_ == 0) b_ = 2 * std::sqrt(k_ * m_);  // critical damping
  HapticState s;
  s.tool = {x_t_, axis_};
  s.device = s.tool;
  write_state(s);
}

HapticLoop::~HapticLoop() {
  stop();
}

double HapticLoop::clock() {
  return seconds(Clock::now());
}

void HapticLoop::start() {
  if (thread_.joinable()) return;
  // A fresh start: the time stopped is neither a period nor a device motion.
  ticked_ = false;
  have_device_ = false;
  {
    std::lock_guard lock(error_mutex_);
    error_.clear();
  }
  stop_.store(false);
  thread_ = std::thread(&HapticLoop::run, this);
}

void HapticLoop::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true);
  thread_.join();
}

void HapticLoop::run() {
  if (settings_.realtime_priority) {
    // Sleeps end within a microsecond of the asked time, and no ordinary thread preempts the
    // loop; a refusal (EPERM) leaves it at normal priority, which stats() reports.
    prctl(PR_SET_TIMERSLACK, 1UL, 0UL, 0UL, 0UL);
    sched_param param{};
    param.sched_priority = std::min(80, sched_get_priority_max(SCHED_FIFO));
    realtime_.store(pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0,
                    std::memory_order_relaxed);
  }
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / settings_.rate_hz));
  const auto margin = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double, std::micro>(settings_.spin_us));
  // Absolute deadlines on a fixed grid: a late tick does not shift the ones after it.
  auto deadline = Clock::now() + period;
  while (!stop_.load(std::memory_order_relaxed)) {
    std::this_thread::sleep_until(deadline - margin);
    while (Clock::now() < deadline) {
    }
    try {
      tick(clock());
    } catch (const std::exception& e) {
      // A device that throws (a driver gone wrong) ends the loop; stop() still joins.
      std::lock_guard lock(error_mutex_);
      error_ = e.what();
      return;
    }
    deadline += period;
    const auto now = Clock::now();
    if (now >= deadline) {
      // Missed one or more deadlines: skip them (no burst of catch-up ticks), stay on the grid.
      deadline += ((now - deadline) / period + 1) * period;
    }
  }
}

void HapticLoop::publish(const HapticSnapshot& snapshot) {
  const std::array<double, 6> cur = {snapshot.sim_time,          snapshot.wall_time,
                                     snapshot.force_on_tool.x(), snapshot.force_on_tool.y(),
                                     snapshot.force_on_tool.z(), double(snapshot.contacts)};
  std::array<double, 12> pair;
  const std::array<double, 6>& prev = publisher_has_prev_ ? publisher_prev_ : cur;
  std::copy(prev.begin(), prev.end(), pair.begin());
  std::copy(cur.begin(), cur.end(), pair.begin() + 6);
  snapshots_.publish(pair);
  publisher_prev_ = cur;
  publisher_has_prev_ = true;
}

void HapticLoop::record_period(double period) {
  periods_.fetch_add(1, std::memory_order_relaxed);
  period_sum_.store(period_sum_.load(std::memory_order_relaxed) + period,
                    std::memory_order_relaxed);
  raise_to(period_max_, period);
  const double bin = std::floor(std::max(period, 0.0) / kBinSeconds);
  const size_t index = bin >= double(kBins) ? kBins : size_t(bin);
  histogram_[index].fetch_add(1, std::memory_order_relaxed);
  if (period * 1e3 > settings_.overrun_ms) overruns_.fetch_add(1, std::memory_order_relaxed);
}

void HapticLoop::tick(double now) {
  const double nominal = 1.0 / settings_.rate_hz;
  double dt = nominal;
  if (ticked_) {
    dt = now - last_tick_;
    record_period(dt);
  }
  ticked_ = true;
  last_tick_ = now;
  ticks_.fetch_add(1, std::memory_order_relaxed);
  if (!(dt > 0)) dt = 0;  // a clock that did not advance: nothing to integrate

  // 1. The device pose and its filtered finite-difference velocity.
  const HapticSample sample = device_->read(now);
  const bool valid = sample.valid && sample.pose.position.allFinite() &&
                     sample.pose.axis.allFinite() && sample.pose.axis.norm() > 0;
  const Vec3 x_d_start = x_d_prev_;
  Vec3 x_d = x_t_;
  if (valid) {
    x_d = sample.pose.position;
    if (have_device_ && dt > 0) {
      const Vec3 raw = (x_d - x_d_prev_) / dt;
      const double alpha = 1 - std::exp(-2 * M_PI * settings_.velocity_cutoff_hz * dt);
      v_d_wall_ += alpha * (raw - v_d_wall_);
    } else {
      v_d_wall_.setZero();
    }
    axis_ = sample.pose.axis.normalized();  // rotation is not force-coupled
  } else {
    v_d_wall_.setZero();
    invalid_.fetch_add(1, std::memory_order_relaxed);
  }
  const bool had_device = have_device_;
  have_device_ = valid;
  x_d_prev_ = x_d;

  // 2. The tissue's force, extrapolated from the physics' last two snapshots.
  if (snapshots_.published() > 0) {
    std::array<double, 12> pair;
    if (snapshots_.read_newest(pair)) {
      if (!have_pair_ || pair[7] != pair_[7]) follow_sim_rate(pair);
      pair_ = pair;
      have_pair_ = true;
    }
  }
  Vec3 f_tissue = Vec3::Zero();
  uint32_t contacts = 0;
  if (have_pair_) {
    contacts = uint32_t(pair_[11]);
    // Contact made or lost between the two snapshots: the force jumped, a line through the
    // jump is no prediction (it would overshoot at the onset and pull at the release), so
    // the newest force is held.
    const bool contact_changed = (pair_[5] > 0) != (pair_[11] > 0);
    f_tissue = contact_changed || !settings_.extrapolate
                   ? get(&pair_[8])
                   : extrapolate_force(pair_[1], get(&pair_[2]), pair_[7], get(&pair_[8]), now);
  }

  // 3. The simulated tool under the virtual coupling, symplectic Euler, over the simulated
  // time that passed during the tick: the physics' rate times the tick's period.
  // Between the physics' first snapshot and the second its rate is not known: the tool holds
  // (it would otherwise advance on the wall clock against a physics that may be far slower).
  const double h_sim = have_pair_ && !sim_rate_known_ ? 0.0 : sim_rate_ * dt;
  // The device's velocity in simulated time, as the tool's (filtered on the wall clock).
  v_d_ = v_d_wall_ / sim_rate_;
  Vec3 f_hand = Vec3::Zero();
  if (valid) {
    f_hand = couple(had_device ? x_d_start : x_d, x_d,
                    std::min(h_sim, kMaxCatchUpPeriods * nominal), f_tissue);
  } else {
    v_t_.setZero();  // coupling off: the tool holds still
  }

  // 4. The force on the hand, clamped.
  uint32_t status = contacts > 0 ? haptic::kStatusInContact : 0;
  const double magnitude = f_hand.norm();
  if (magnitude > max_force_) {
    f_hand *= max_force_ / magnitude;
    status |= haptic::kStatusClamped;
    clamped_.fetch_add(1, std::memory_order_relaxed);
  }
  if (ticks_.load(std::memory_order_relaxed) > 1)
    raise_to(max_jump_, (f_hand - last_force_).norm());
  raise_to(max_force_seen_, f_hand.norm());
  last_force_ = f_hand;
  device_->send(f_hand, now, status);

  HapticState s;
  s.wall_time = now;
  s.sim_time = have_pair_ ? pair_[6] : 0;
  s.tool = {x_t_, axis_};
  s.tool_velocity = v_t_;
  s.device = {x_d, axis_};
  s.force_on_hand = f_hand;
  s.tissue_force = f_tissue;
  s.status = status;
  s.contacts = contacts;
  s.device_valid = valid;
  write_state(s);
}

Vec3 HapticLoop::couple(const Vec3& x_d_start, const Vec3& x_d, double h_total,
                        const Vec3& f_tissue) {
  const double nominal = 1.0 / settings_.rate_hz;
  const double omega = std::sqrt(k_ / m_);
  const double h_stable = std::min({nominal, 0.5 / omega, 0.5 * m_ / b_});
  const int n =
      h_total > 0 ? std::clamp(int(std::ceil(h_total / h_stable - 1e-9)), 1, kMaxSubsteps) : 0;
  const double h = n > 0 ? h_total / n : 0;
  Vec3 sum = Vec3::Zero();
  bool limited = false;
  for (int i = 0; i < n; ++i) {
    // The device moved linearly during the tick (from where it was when it was last valid).
    const Vec3 x_di = x_d_start + (x_d - x_d_start) * (double(i + 1) / n);
    const Vec3 f_c = k_ * (x_di - x_t_) + b_ * (v_d_ - v_t_);
    v_t_ += h * (f_c + f_tissue) / m_;
    // The tool's top speed (simulated time): beyond it the tissue cannot follow; the tool
    // lags its device and the hand feels the stretched spring.
    const double speed = v_t_.norm();
    if (speed > max_speed_) {
      v_t_ *= max_speed_ / speed;
      limited = true;
    }
    x_t_ += h * v_t_;
    sum += f_c;
  }
  if (limited) speed_limited_.fetch_add(1, std::memory_order_relaxed);
  return n > 0 ? Vec3(-sum / n) : Vec3(-(k_ * (x_d - x_t_) + b_ * (v_d_ - v_t_)));
}

void HapticLoop::follow_sim_rate(const std::array<double, 12>& pair) {
  const double d_sim = pair[6] - pair[0], d_wall = pair[7] - pair[1];
  if (!(d_wall > 0) || !(d_sim >= 0)) return;  // a first snapshot, or a clock gone backwards
  sim_rate_known_ = true;
  const double keep = std::exp(-d_wall / kSimRateSeconds);
  sim_seconds_ = keep * sim_seconds_ + d_sim;
  wall_seconds_ = keep * wall_seconds_ + d_wall;
  sim_rate_ = std::min(1.0, sim_seconds_ / wall_seconds_);
  if (!(sim_rate_ > kMinSimRate)) sim_rate_ = kMinSimRate;
}

void HapticLoop::write_state(const HapticState& s) {
  std::array<double, kStateWords> w{};
  w[0] = s.wall_time;
  w[1] = s.sim_time;
  put(&w[2], s.tool.position);
  put(&w[5], s.tool.axis);
  put(&w[8], s.tool_velocity);
  put(&w[11], s.device.position);
  put(&w[14], s.device.axis);
  put(&w[17], s.force_on_hand);
  put(&w[20], s.tissue_force);
  w[23] = s.status;
  w[24] = s.contacts;
  w[25] = s.device_valid ? 1 : 0;
  state_.publish(w);
}

HapticState HapticLoop::state() const {
  std::array<double, kStateWords> w;
  while (!state_.read_newest(w)) {
  }
  HapticState s;
  s.wall_time = w[0];
  s.sim_time = w[1];
  s.tool = {get(&w[2]), get(&w[5])};
  s.tool_velocity = get(&w[8]);
  s.device = {get(&w[11]), get(&w[14])};
  s.force_on_hand = get(&w[17]);
  s.tissue_force = get(&w[20]);
  s.status = uint32_t(w[23]);
  s.contacts = uint32_t(w[24]);
  s.device_valid = w[25] != 0;
  return s;
}

ToolPose HapticLoop::tool_pose() const {
  return state().tool;
}

std::string HapticLoop::error() const {
  std::lock_guard lock(error_mutex_);
  return error_;
}

HapticStats HapticLoop::stats() const {
  HapticStats out;
  out.ticks = ticks_.load(std::memory_order_relaxed);
  out.overruns = overruns_.load(std::memory_order_relaxed);
  out.clamped_ticks = clamped_.load(std::memory_order_relaxed);
  out.top_speed = max_speed_;
  out.speed_limited_ticks = speed_limited_.load(std::memory_order_relaxed);
  out.invalid_ticks = invalid_.load(std::memory_order_relaxed);
  out.max_force_jump = max_jump_.load(std::memory_order_relaxed);
  out.max_hand_force = max_force_seen_.load(std::memory_order_relaxed);
  out.snapshots = snapshots_.published();
  out.realtime_priority = realtime_.load(std::memory_order_relaxed);
  const uint64_t n = periods_.load(std::memory_order_relaxed);
  if (n == 0) return out;
  const double max = period_max_.load(std::memory_order_relaxed);
  out.period_mean_ms = 1e3 * period_sum_.load(std::memory_order_relaxed) / double(n);
  out.period_max_ms = 1e3 * max;
  // p99: the upper edge of the bin holding the 99th percentile (10 us resolution), at most max.
  const uint64_t rank = uint64_t(std::ceil(0.99 * double(n)));
  uint64_t seen = 0;
  double p99 = max;
  for (size_t i = 0; i < kBins; ++i) {
    seen += histogram_[i].load(std::memory_order_relaxed);
    if (seen >= rank) {
      p99 = std::min(max, double(i + 1) * kBinSeconds);
      break;
    }
  }
  out.period_p99_ms = 1e3 * p99;
  return out;
}

}  // namespace phyxel
