// The haptic loop (docs/haptics.md): one per haptic tool, a thread ticking at 1 kHz that
// couples the device to a simulated tool and sends the force on the hand. It never waits on
// the solver: the physics publishes snapshots of the tissue's force on the tool (publish(),
// wait-free), and reads the simulated tool's pose back (tool_pose(), lock-free).
//
// Each tick, at the wall time t:
//  1. the device pose x_d (the velocity v_d by a finite difference, low-pass filtered);
//  2. the tissue's force on the tool, extrapolated linearly from the last two snapshots
//     (Picinbono, Lombardo, Delingette and Ayache 2002, "Improving realism of a surgery
//     simulator: linear anisotropic elasticity, complex interactions and force extrapolation",
//     J. Visualization and Computer Animation 13(3), the paper's reference [28]):
//       F(t) = F_k + (F_k - F_{k-1}) (t - t_k) / (t_k - t_{k-1}),
//     the horizon t - t_k clamped to [0, t_k - t_{k-1}] (one physics period); where contact
//     was made or lost between the two (one has contacts, the other none) the force jumped
//     and F_k is held instead;
//  3. the simulated tool (mass m) under the virtual coupling (Colgate, Stanley and Brown
//     1995, "Issues in the haptic display of tool use", IROS):
//       m a = k (x_d - x_t) + b (v_d - v_t) + F_tissue,
//     semi-implicit (symplectic) Euler over the simulated time of the tick (its measured period
//     times the physics' rate r, simulated seconds per wall second from the snapshots over
//     about 0.1 s, at most 1), split into substeps where that is long or k, b make one step
//     unstable; v_d is the device's velocity in simulated time (its wall velocity / r);
//     b = 2 sqrt(k m) (critical) when CouplingSettings::damping is 0. At r = 1 this is the
//     wall clock; below, the tool meets the tissue as fast as in real time, not 1/r times
//     faster (which drove slow solvers' tissue unstable);
//  4. the force on the hand F_hand = -(k (x_d - x_t) + b (v_d - v_t)), the mean over the
//     substeps (so the hand gets exactly the opposite of the coupling's impulse on the tool),
//     clamped to max_force.
// Rotation is not force-coupled: the simulated tool's axis is the device's axis. While the
// device has no valid pose the coupling is off: the tool holds still and the hand gets zero.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "engine/scene/tool_desc.h"
#include "engine/surgery/haptic_device.h"
#include "engine/surgery/seqlock.h"

namespace phyxel {

// What the physics publishes after each update.
struct HapticSnapshot {
  double sim_time = 0;                // s, simulated time of the update
  double wall_time = 0;               // s, HapticLoop::clock() when the force was computed
  Vec3 force_on_tool = Vec3::Zero();  // N, the tissue's force on the tool
  uint32_t contacts = 0;              // phyxels in contact
};

struct HapticLoopSettings {
  double rate_hz = 1000;            // tick rate
  double velocity_cutoff_hz = 100;  // low-pass of the device's finite-difference velocity
  double overrun_ms = 2;            // a period longer than this is an overrun
  double spin_us = 200;             // sleep until this long before the deadline, then spin
  bool extrapolate = true;          // false: hold the newest force (zero-order hold)
  // Ask for real-time scheduling (SCHED_FIFO) and a 1 ns timer slack for the loop's thread;
  // where the OS refuses (no CAP_SYS_NICE, no rtprio limit) it runs at normal priority.
  bool realtime_priority = true;
};

// The loop's latest state, for the physics and for display.
struct HapticState {
  double wall_time = 0;  // s, of the tick that wrote it
  double sim_time = 0;   // s, of the newest snapshot used
  ToolPose tool;         // the simulated tool
  Vec3 tool_velocity = Vec3::Zero();
  ToolPose device;                    // the device's pose (the tool's while none)
  Vec3 force_on_hand = Vec3::Zero();  // N, as sent (clamped)
  Vec3 tissue_force = Vec3::Zero();   // N, the extrapolated force on the tool
  uint32_t status = 0;                // haptic::kStatus* flags
  uint32_t contacts = 0;              // of the newest snapshot used
  bool device_valid = false;
};

struct HapticStats {
  uint64_t ticks = 0;
  double period_mean_ms = 0, period_p99_ms = 0, period_max_ms = 0;  // tick to tick
  uint64_t overruns = 0;             // periods above HapticLoopSettings::overrun_ms
  double max_force_jump = 0;         // N, largest |F_hand(n) - F_hand(n-1)|
  double max_hand_force = 0;         // N, largest |F_hand| sent (after the clamp)
  uint64_t clamped_ticks = 0;        // ticks whose force was clamped
  double top_speed = 0;              // m/s, simulated time (infinite: none)
  uint64_t speed_limited_ticks = 0;  // ticks in which the tool was held to it (it lagged)
  uint64_t invalid_ticks = 0;        // ticks without a valid device pose
  uint64_t snapshots = 0;            // snapshots published
  // The thread got real-time scheduling (SCHED_FIFO; needs CAP_SYS_NICE or an rtprio limit):
  // without it the OS may preempt the loop for milliseconds on a busy machine.
  bool realtime_priority = false;
};

class HapticLoop {
 public:
  // `initial`: the simulated tool's pose before the device gives one (the tool's path start).
  // Throws std::invalid_argument on non-positive stiffness, mass, max_force or rate, or
  // negative damping or max_speed. A max_speed of 0 leaves the tool's speed unbounded
  // (HapticSession passes the scene's, live_tool_speed).
  HapticLoop(std::shared_ptr<HapticDevice> device, const CouplingSettings& coupling,
             const ToolPose& initial, const HapticLoopSettings& settings = {});
  ~HapticLoop();
  HapticLoop(const HapticLoop&) = delete;
  HapticLoop& operator=(const HapticLoop&) = delete;

  // The thread: idempotent; stop() joins it. Do not call tick() while it runs.
  void start();
  void stop();
  bool running() const { return thread_.joinable(); }  // started and not stopped
  // Why the thread ended on its own (the device threw); empty while it runs or stopped cleanly.
  std::string error() const;

  // One tick at wall time `now` (s, HapticLoop::clock() or any monotonic clock in tests).
  // The thread calls it on its deadlines; tests call it directly.
  void tick(double now);

  // Physics side (one publishing thread): wait-free.
  void publish(const HapticSnapshot& snapshot);
  // The simulated tool's pose, lock-free (a retry only if two ticks wrote during the read).
  ToolPose tool_pose() const;
  HapticState state() const;
  HapticStats stats() const;

  const HapticDevice& device() const { return *device_; }
  double damping() const { return b_; }  // N s/m, the one in use

  // Seconds of std::chrono::steady_clock: the clock of tick(), snapshots and devices.
  static double clock();

 private:
  void run();
  void record_period(double period);
  void write_state(const HapticState& s);
  // A new pair of snapshots: the physics' rate, sim_rate_.
  void follow_sim_rate(const std::array<double, 12>& pair);
  // Step 3: the simulated tool over h_total s of simulated time, the device moving linearly
  // from x_d_start to x_d; returns the force on the hand (before its clamp).
  Vec3 couple(const Vec3& x_d_start, const Vec3& x_d, double h_total, const Vec3& f_tissue);

  std::shared_ptr<HapticDevice> device_;
  double k_, b_, m_, max_force_;
  double max_speed_;  // m/s, simulated time; infinite when the coupling gives 0
  HapticLoopSettings settings_;

  // The loop's own state (the ticking thread only).
  double last_tick_ = 0;
  bool ticked_ = false;
  Vec3 x_t_, v_t_ = Vec3::Zero();
  Vec3 axis_;
  Vec3 x_d_prev_ = Vec3::Zero(), v_d_ = Vec3::Zero();
  Vec3 v_d_wall_ = Vec3::Zero();  // the device's filtered velocity on the wall clock
  // Simulated seconds per wall second of the physics, <= 1 (1 until it published twice): the
  // coupled tool advances by sim_rate_ times each tick's period, so that a physics slower than
  // real time meets the tool at the speeds it would have in real time.
  double sim_rate_ = 1;
  double sim_seconds_ = 0, wall_seconds_ = 0;  // the decaying sums sim_rate_ is the ratio of
  bool sim_rate_known_ = false;                // two snapshots at different wall times were read
  bool have_device_ = false;
  Vec3 last_force_ = Vec3::Zero();
  // The newest pair of snapshots read: (prev, cur) x (sim_time, wall_time, fx, fy, fz, contacts).
  std::array<double, 12> pair_{};
  bool have_pair_ = false;

  // Shared with other threads.
  std::atomic<bool> stop_{false};
  std::atomic<bool> realtime_{false};
  std::thread thread_;
  mutable std::mutex error_mutex_;
  std::string error_;
  DoubleBuffer<12> snapshots_;              // the physics' last two snapshots (prev, cur)
  std::array<double, 6> publisher_prev_{};  // the publishing thread's last snapshot
  bool publisher_has_prev_ = false;
  static constexpr size_t kStateWords = 26;
  DoubleBuffer<kStateWords> state_;

  // Statistics: written by the ticking thread, read by stats(), all relaxed atomics.
  static constexpr size_t kBins = 10000;  // 10 us bins up to 100 ms, then an overflow bin
  static constexpr double kBinSeconds = 1e-5;
  std::array<std::atomic<uint32_t>, kBins + 1> histogram_{};
  std::atomic<uint64_t> ticks_{0}, periods_{0}, overruns_{0}, clamped_{0}, invalid_{0};
  std::atomic<uint64_t> speed_limited_{0};
  std::atomic<double> period_sum_{0}, period_max_{0}, max_jump_{0}, max_force_seen_{0};
};

// The extrapolated tissue force at wall time t from the snapshots (t_{k-1}, F_{k-1}) and
// (t_k, F_k): linear, the horizon clamped to [0, t_k - t_{k-1}]; F_k alone when
// t_k <= t_{k-1} (a single snapshot: pass it twice).
Vec3 extrapolate_force(double t_prev, const Vec3& f_prev, double t_cur, const Vec3& f_cur,
                       double t);

}  // namespace phyxel
