// Timestamp queries and the copy-bandwidth measurement return usable numbers. No thresholds:
// timing never decides a test.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "compute/kernels.h"
#include "compute/timing.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

class TimingTest : public VulkanTest {};

TEST_F(TimingTest, PassTimerMeasuresEachPass) {
  const CoreKernels kernels(ctx());
  const uint32_t n = 1000;
  const Buffer dst(ctx(), n * sizeof(uint32_t), MemoryIntent::Device, "timed");
  PassTimer timer(ctx(), 4);
  EXPECT_EQ(timer.supported(), ctx().timestamps());
  Recorder rec(ctx(), "timed");
  for (int round = 0; round < 2; ++round) {
    timer.reset(rec);
    timer.begin(rec, "iota");
    dispatch(rec, kernels.iota, layout::IotaPush{n, 0}, {dst}, n);
    timer.end(rec);
    rec.barrier();
    timer.begin(rec, "fill");
    rec.fill(dst, 0);
    timer.end(rec);
    rec.submit_and_wait();
    const std::vector<PassTime> times = timer.results();
    if (!timer.supported()) {
      EXPECT_TRUE(times.empty());
      continue;
    }
    ASSERT_EQ(times.size(), 2u);
    EXPECT_EQ(times[0].name, "iota");
    EXPECT_EQ(times[1].name, "fill");
    for (const PassTime& t : times) {
      EXPECT_TRUE(std::isfinite(t.ns)) << t.name;
      EXPECT_GE(t.ns, 0.0) << t.name;
    }
  }
}

TEST_F(TimingTest, PassTimerRejectsMisuse) {
  PassTimer timer(ctx(), 1);
  Recorder rec(ctx(), "misuse");
  EXPECT_THROW(timer.end(rec), std::logic_error);
  timer.reset(rec);
  timer.begin(rec, "a");
  EXPECT_THROW(timer.begin(rec, "nested"), std::logic_error);
  timer.end(rec);
  EXPECT_THROW(timer.begin(rec, "too many"), std::logic_error);
  rec.submit_and_wait();
}

TEST_F(TimingTest, CopyBandwidthIsPositiveAndFinite) {
  const CopyBandwidth bw = measure_copy_bandwidth(ctx(), uint64_t{8} << 20, 3);
  EXPECT_EQ(bw.bytes, uint64_t{8} << 20);
  EXPECT_EQ(bw.timestamps, ctx().timestamps());
  EXPECT_TRUE(std::isfinite(bw.seconds));
  EXPECT_GT(bw.seconds, 0.0);
  EXPECT_TRUE(std::isfinite(bw.gb_per_s));
  EXPECT_GT(bw.gb_per_s, 0.0);
  EXPECT_DOUBLE_EQ(bw.gb_per_s, 2.0 * static_cast<double>(bw.bytes) / bw.seconds / 1e9);
  EXPECT_GT(bw.dma_seconds, 0.0);
  EXPECT_DOUBLE_EQ(bw.dma_gb_per_s, 2.0 * static_cast<double>(bw.bytes) / bw.dma_seconds / 1e9);
  EXPECT_THROW(measure_copy_bandwidth(ctx(), 6, 1), std::invalid_argument);
  EXPECT_THROW(measure_copy_bandwidth(ctx(), 24, 1), std::invalid_argument);  // not 16-aligned
  EXPECT_THROW(measure_copy_bandwidth(ctx(), 64, 0), std::invalid_argument);
}

// The roofline's buffer: far past a GPU's caches, small on a CPU driver (lavapipe here).
TEST_F(TimingTest, BandwidthProbeSizeFollowsTheDevice) {
  const uint64_t bytes = default_bandwidth_bytes(ctx());
  if (ctx().info().type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    EXPECT_EQ(bytes, uint64_t{64} << 20);
  } else {
    EXPECT_GE(bytes, uint64_t{64} << 20);
  }
  EXPECT_EQ(bytes % 16, 0u);
}

}  // namespace
}  // namespace phyxel::gpu
