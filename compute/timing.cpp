#include "compute/timing.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <vector>

#include "compute/buffer.h"
#include "compute/pipeline.h"
#include "compute/shaders/layout.h"
#include "phyxel_spv/stream_copy.spv.h"

namespace phyxel::gpu {

PassTimer::PassTimer(Context& ctx, uint32_t max_passes) : ctx_(&ctx), max_passes_(max_passes) {
  if (!ctx.timestamps() || max_passes == 0) return;
  auto info = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2 * max_passes;
  VK_CHECK(ctx.fn().vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_));
}

PassTimer::~PassTimer() {
  if (pool_ != VK_NULL_HANDLE && !ctx_->abandoned())
    ctx_->fn().vkDestroyQueryPool(ctx_->device(), pool_, nullptr);
}

void PassTimer::reset(Recorder& rec) {
  names_.clear();
  open_ = false;
  if (!supported()) return;
  ctx_->fn().vkCmdResetQueryPool(rec.cmd(), pool_, 0, 2 * max_passes_);
  was_reset_ = true;
}

void PassTimer::begin(Recorder& rec, const std::string& name) {
  if (open_) throw std::logic_error("PassTimer: begin('" + name + "') inside another pass");
  if (names_.size() >= max_passes_) {
    throw std::logic_error("PassTimer: more than " + std::to_string(max_passes_) + " passes");
  }
  if (supported() && !was_reset_) throw std::logic_error("PassTimer: begin() before reset()");
  open_ = true;
  if (supported()) {
    const uint32_t query = 2 * static_cast<uint32_t>(names_.size());
    ctx_->fn().vkCmdWriteTimestamp(rec.cmd(), VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, query);
  }
  names_.push_back(name);
}

void PassTimer::end(Recorder& rec) {
  if (!open_) throw std::logic_error("PassTimer: end() without begin()");
  open_ = false;
  if (supported()) {
    const uint32_t query = 2 * static_cast<uint32_t>(names_.size() - 1) + 1;
    ctx_->fn().vkCmdWriteTimestamp(rec.cmd(), VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_, query);
  }
}

std::vector<PassTime> PassTimer::results() const {
  std::vector<PassTime> out;
  if (!supported() || names_.empty()) return out;
  if (open_) throw std::logic_error("PassTimer: results() with a pass still open");
  const uint32_t queries = 2 * static_cast<uint32_t>(names_.size());
  std::vector<uint64_t> stamps(queries);
  VK_CHECK(ctx_->fn().vkGetQueryPoolResults(
      ctx_->device(), pool_, 0, queries, stamps.size() * sizeof(uint64_t), stamps.data(),
      sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  const uint32_t bits = ctx_->info().timestamp_valid_bits;
  const uint64_t mask = bits >= 64 ? ~uint64_t{0} : (uint64_t{1} << bits) - 1;
  const double period = ctx_->info().timestamp_period_ns;
  for (size_t i = 0; i < names_.size(); ++i) {
    const uint64_t ticks = (stamps[2 * i + 1] - stamps[2 * i]) & mask;  // survives a wrap
    out.push_back({names_[i], static_cast<double>(ticks) * period});
  }
  return out;
}

namespace {

// Median duration of `repeats` runs of `record` (one pass each), by timestamps when the device
// has them, else by the host clock around each submission.
template <class Record>
double median_seconds(Context& ctx, int repeats, const Record& record, bool& timestamps) {
  std::vector<double> seconds;
  Recorder rec(ctx, "bandwidth probe");
  PassTimer timer(ctx, static_cast<uint32_t>(repeats));
  timestamps = timer.supported();
  if (timestamps) {
    timer.reset(rec);
    for (int i = 0; i < repeats; ++i) {
      timer.begin(rec, "copy");
      record(rec);
      timer.end(rec);
      rec.barrier();
    }
    rec.submit_and_wait();
    for (const PassTime& t : timer.results()) seconds.push_back(t.ns * 1e-9);
  } else {
    for (int i = 0; i < repeats; ++i) {
      record(rec);
      const auto start = std::chrono::steady_clock::now();
      rec.submit_and_wait();
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  }
  std::sort(seconds.begin(), seconds.end());
  return seconds[seconds.size() / 2];
}

// Read + write traffic of copying `bytes` in `seconds`, as STREAM counts it; 0 for a time that
// a timer tick or two on a tiny copy can read as 0 (rather than infinity).
double traffic_gb_per_s(uint64_t bytes, double seconds) {
  return seconds > 0 ? 2.0 * static_cast<double>(bytes) / seconds / 1e9 : 0.0;
}

}  // namespace

uint64_t default_bandwidth_bytes(const Context& ctx) {
  const DeviceInfo& info = ctx.info();
  // A CPU driver copies through the same caches and memory as the host: 64 MiB (well past
  // its caches, and quick for the tests that run on lavapipe). A GPU: 1 GiB, far past its
  // L2 (50 MB on an H100), when its memory holds two with room to spare.
  const uint64_t gpu_bytes = uint64_t{1} << 30;
  if (info.type == VK_PHYSICAL_DEVICE_TYPE_CPU || info.device_local_bytes < 8 * gpu_bytes ||
      info.max_storage_buffer_range < gpu_bytes)
    return uint64_t{64} << 20;
  return gpu_bytes;
}

CopyBandwidth measure_copy_bandwidth(Context& ctx, uint64_t bytes, int repeats) {
  if (bytes == 0) bytes = default_bandwidth_bytes(ctx);
  if (bytes % 16 != 0 || repeats < 1 || bytes / 16 > UINT32_MAX ||
      bytes > ctx.info().max_storage_buffer_range) {
    throw std::invalid_argument(
        "measure_copy_bandwidth: bytes must be a positive multiple of 16 that one storage buffer "
        "binding holds, repeats at least 1");
  }
  ctx.check_fits(2 * bytes);
  Buffer src(ctx, bytes, MemoryIntent::Device, "bandwidth source");
  Buffer dst(ctx, bytes, MemoryIntent::Device, "bandwidth destination");
  const Pipeline kernel(ctx, PHYXEL_SHADER(stream_copy), 2, sizeof(layout::StreamCopyPush));
  layout::StreamCopyPush push{};
  push.count = static_cast<uint32_t>(bytes / 16);
  push.per_thread = 4;
  push.threads = (push.count + push.per_thread - 1) / push.per_thread;
  const auto stream_copy = [&](Recorder& rec) {
    dispatch(rec, kernel, push, {{"Src", src}, {"Dst", dst}}, push.threads);
  };
  const auto dma_copy = [&](Recorder& rec) { rec.copy(src, dst); };
  {
    // Warm-up: first touch of both buffers, caches, and clocks raised by a few hundred
    // milliseconds of work at most.
    Recorder rec(ctx, "bandwidth warm-up");
    rec.fill(src, 0x3f800000u);
    rec.fill(dst, 0u);
    rec.barrier();
    const int warm = std::clamp<int>(static_cast<int>((uint64_t{16} << 30) / bytes), 2, 64);
    for (int i = 0; i < warm; ++i) {
      stream_copy(rec);
      rec.barrier();
      dma_copy(rec);
      rec.barrier();
    }
    rec.submit_and_wait();
  }
  CopyBandwidth result;
  result.bytes = bytes;
  result.seconds = median_seconds(ctx, repeats, stream_copy, result.timestamps);
  result.gb_per_s = traffic_gb_per_s(bytes, result.seconds);
  result.dma_seconds = median_seconds(ctx, repeats, dma_copy, result.timestamps);
  result.dma_gb_per_s = traffic_gb_per_s(bytes, result.dma_seconds);
  // The kernel must have copied: a probe that measured nothing would flatter every roofline.
  {
    Recorder rec(ctx, "bandwidth check");
    rec.fill(dst, 0u);
    rec.barrier();
    stream_copy(rec);
    rec.submit_and_wait();
  }
  const size_t words = static_cast<size_t>(std::min<uint64_t>(bytes, 4096) / 4);
  const std::vector<uint32_t> head = download<uint32_t>(ctx, dst, words);
  const std::vector<uint32_t> tail = download<uint32_t>(ctx, dst, words, bytes - words * 4);
  const auto copied = [](uint32_t w) { return w == 0x3f800000u; };
  if (!std::all_of(head.begin(), head.end(), copied) ||
      !std::all_of(tail.begin(), tail.end(), copied))
    throw std::runtime_error(ctx.info().name + ": the bandwidth probe's copy kernel did not copy");
  return result;
}

LaunchFloor measure_launch_floor(Context& ctx, uint32_t invocations, int dispatches, int repeats) {
  if (invocations == 0 || dispatches < 1 || repeats < 1)
    throw std::invalid_argument("measure_launch_floor: invocations, dispatches, repeats >= 1");
  const uint64_t bytes = uint64_t{invocations} * 16;
  Buffer src(ctx, bytes, MemoryIntent::Device, "launch probe source");
  Buffer dst(ctx, bytes, MemoryIntent::Device, "launch probe destination");
  const Pipeline kernel(ctx, PHYXEL_SHADER(stream_copy), 2, sizeof(layout::StreamCopyPush));
  layout::StreamCopyPush push{};
  push.count = invocations;
  push.per_thread = 1;
  push.threads = invocations;
  {
    Recorder rec(ctx, "launch probe warm-up");
    rec.fill(src, 0u);
    rec.barrier();
    for (int i = 0; i < dispatches; ++i) {
      dispatch(rec, kernel, push, {{"Src", src}, {"Dst", dst}}, push.threads);
      rec.barrier();
    }
    rec.submit_and_wait();
  }
  LaunchFloor result;
  result.invocations = invocations;
  result.dispatches = dispatches;
  const auto per_dispatch_us = [&](int kind) {
    const double seconds = median_seconds(
        ctx, repeats,
        [&](Recorder& rec) {
          for (int i = 0; i < dispatches; ++i) {
            // Alternate the direction, so that each dispatch reads what the last one wrote.
            if (i % 2 == 0)
              dispatch(rec, kernel, push, {{"Src", src}, {"Dst", dst}}, push.threads);
            else
              dispatch(rec, kernel, push, {{"Src", dst}, {"Dst", src}}, push.threads);
            if (kind == 0) rec.barrier();
            if (kind == 1) rec.compute_barrier();
          }
        },
        result.timestamps);
    return seconds / dispatches * 1e6;
  };
  result.barrier_us = per_dispatch_us(0);
  result.compute_barrier_us = per_dispatch_us(1);
  result.no_barrier_us = per_dispatch_us(2);
  return result;
}

}  // namespace phyxel::gpu
