// GPU timing: per-pass durations from timestamp queries, and the device's copy bandwidth
// (the roofline that `phyxel bench` compares the solver passes with). Timing is for bench
// and logs; a test never passes or fails on a time.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/recorder.h"

namespace phyxel::gpu {

struct PassTime {
  std::string name;
  double ns = 0;
};

// Usage, per submit:
//   timer.reset(rec);
//   timer.begin(rec, "forces"); dispatch(...); timer.end(rec);
//   rec.submit_and_wait();
//   for (const PassTime& t : timer.results()) ...
// Where the queue has no timestamps (timestampValidBits == 0) supported() is false, begin/end
// record nothing and results() is empty.
class PassTimer {
 public:
  explicit PassTimer(Context& ctx, uint32_t max_passes = 64);
  ~PassTimer();
  PassTimer(const PassTimer&) = delete;
  PassTimer& operator=(const PassTimer&) = delete;

  bool supported() const { return pool_ != VK_NULL_HANDLE; }
  uint32_t max_passes() const { return max_passes_; }

  void reset(Recorder& rec);  // forgets earlier passes; records the query reset
  // Timestamps after all earlier commands finished / after the pass finished. Passes do not
  // nest; more than max_passes() since reset() throw.
  void begin(Recorder& rec, const std::string& name);
  void end(Recorder& rec);
  // After the recorder's wait(): durations of the passes since reset(), in order.
  std::vector<PassTime> results() const;

 private:
  Context* ctx_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t max_passes_;
  std::vector<std::string> names_;
  bool open_ = false;
  bool was_reset_ = false;
};

struct CopyBandwidth {
  uint64_t bytes = 0;       // size of the buffer copied
  double seconds = 0;       // median duration of one copy by the stream_copy kernel
  double gb_per_s = 0;      // its memory traffic, read + written (2 * bytes / seconds / 1e9), as
                            // STREAM counts it: the roofline the solver is compared with
  double dma_seconds = 0;   // the same copy by vkCmdCopyBuffer (on NVIDIA a copy engine, which
  double dma_gb_per_s = 0;  // streams at a fraction of what the shader cores do)
  bool timestamps = false;  // false: timed with the host clock around submit and wait
};

// The probe's buffer size for `ctx`: 1 GiB on a GPU whose memory holds 8 GiB or more (far past
// its caches), 64 MiB on a CPU driver or a small GPU.
uint64_t default_bandwidth_bytes(const Context& ctx);

// Copies a `bytes` device buffer (0: default_bandwidth_bytes) to another `repeats` times with
// the stream_copy kernel and `repeats` times with vkCmdCopyBuffer, after a warm-up of both
// (clocks, caches, first touch), and reports the medians. Checks that 2 * bytes fit first,
// and that the kernel copied (throws std::runtime_error naming the device when not). Throws
// std::invalid_argument for a size that is not a positive multiple of 16 within one binding.
CopyBandwidth measure_copy_bandwidth(Context& ctx, uint64_t bytes = 0, int repeats = 9);

// What a dependent dispatch costs when its work is negligible: the floor of a small scene's
// step (two dispatches per step). The stream_copy kernel over `invocations` vec4s, recorded
// `dispatches` times in one command buffer, median of `repeats`, per dispatch.
struct LaunchFloor {
  uint32_t invocations = 0;
  int dispatches = 0;
  double barrier_us = 0;          // Recorder::barrier() between dispatches (compute + transfer)
  double compute_barrier_us = 0;  // Recorder::compute_barrier() (compute to compute only)
  double no_barrier_us = 0;       // no barrier: the dispatches may overlap
  bool timestamps = false;
};
LaunchFloor measure_launch_floor(Context& ctx, uint32_t invocations = 8192, int dispatches = 1000,
                                 int repeats = 5);

}  // namespace phyxel::gpu
