#include "compute/timing.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace phyxel::gpu {

PassTimer::PassTimer(Context& ctx, uint32_t max_passes) : ctx_(&ctx), max_passes_(max_passes) {
  if (!ctx.timestamps() || max_passes == 0) return;
  auto info = vk_struct<VkQueryPoolCreateInfo>(VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO);
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = 2 * max_passes;
  VK_CHECK(ctx.fn().vkCreateQueryPool(ctx.device(), &info, nullptr, &pool_));
}

PassTimer::~PassTimer() {
  if (pool_ != VK_NULL_HANDLE) ctx_->fn().vkDestroyQueryPool(ctx_->device(), pool_, nullptr);
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

CopyBandwidth measure_copy_bandwidth(Context& ctx, uint64_t bytes, int repeats) {
  if (bytes == 0 || bytes % 4 != 0 || repeats < 1) {
    throw std::invalid_argument("measure_copy_bandwidth: bytes must be a positive multiple of 4");
  }
  ctx.check_fits(2 * bytes);
  Buffer src(ctx, bytes, MemoryIntent::Device, "bandwidth source");
  Buffer dst(ctx, bytes, MemoryIntent::Device, "bandwidth destination");
  Recorder rec(ctx, "copy bandwidth");
  rec.fill(src, 0x3f800000u);
  rec.barrier();
  rec.copy(src, dst);  // warm-up: first touch of dst, caches, clocks
  rec.barrier();

  CopyBandwidth result;
  result.bytes = bytes;
  std::vector<double> seconds;
  PassTimer timer(ctx, static_cast<uint32_t>(repeats));
  result.timestamps = timer.supported();
  if (result.timestamps) {
    timer.reset(rec);
    for (int i = 0; i < repeats; ++i) {
      timer.begin(rec, "copy");
      rec.copy(src, dst);
      timer.end(rec);
      rec.barrier();
    }
    rec.submit_and_wait();
    for (const PassTime& t : timer.results()) seconds.push_back(t.ns * 1e-9);
  } else {
    rec.submit_and_wait();
    for (int i = 0; i < repeats; ++i) {
      rec.copy(src, dst);
      const auto start = std::chrono::steady_clock::now();
      rec.submit_and_wait();
      seconds.push_back(
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
  }
  std::sort(seconds.begin(), seconds.end());
  result.seconds = seconds[seconds.size() / 2];
  // A timer tick or two on a tiny copy can read 0: report no bandwidth rather than infinity.
  result.gb_per_s =
      result.seconds > 0 ? 2.0 * static_cast<double>(bytes) / result.seconds / 1e9 : 0.0;
  return result;
}

}  // namespace phyxel::gpu
