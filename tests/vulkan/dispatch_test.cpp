// The whole chain (embedded SPIR-V → pipeline → dispatch → readback) and the dispatch helper:
// group rounding, push-constant and binding checks, the descriptor paths, many dispatches
// per submit, two contexts at once.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "compute/kernels.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

constexpr uint32_t kSentinel = 0xdeadbeefu;
constexpr uint32_t kPad = 200;  // elements past the end that must stay untouched

TEST(GroupCounts, RoundUp) {
  const std::array<uint32_t, 3> max = {65535, 65535, 65535};
  EXPECT_EQ(group_counts(0, 64, max), (std::array<uint32_t, 3>{0, 0, 0}));
  EXPECT_EQ(group_counts(1, 64, max), (std::array<uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(group_counts(13, 64, max), (std::array<uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(group_counts(64, 64, max), (std::array<uint32_t, 3>{1, 1, 1}));
  EXPECT_EQ(group_counts(65, 64, max), (std::array<uint32_t, 3>{2, 1, 1}));
  EXPECT_EQ(group_counts(127, 64, max), (std::array<uint32_t, 3>{2, 1, 1}));
  EXPECT_EQ(group_counts(1000, 64, max), (std::array<uint32_t, 3>{16, 1, 1}));
  EXPECT_EQ(group_counts(UINT32_MAX, 1024, max), (std::array<uint32_t, 3>{65535, 65, 1}));
}

TEST(GroupCounts, SpillIntoYBeyondTheXLimit) {
  const std::array<uint32_t, 3> max = {4, 3, 1};
  EXPECT_EQ(group_counts(4 * 64, 64, max), (std::array<uint32_t, 3>{4, 1, 1}));
  EXPECT_EQ(group_counts(4 * 64 + 1, 64, max), (std::array<uint32_t, 3>{4, 2, 1}));
  EXPECT_EQ(group_counts(12 * 64, 64, max), (std::array<uint32_t, 3>{4, 3, 1}));
  EXPECT_THROW(group_counts(12 * 64 + 1, 64, max), VulkanError);
}

TEST(SpirvWorkgroupSize, ReadsLocalSizeAndRejectsGarbage) {
  // Header, then OpExecutionMode %1 LocalSize 32 4 1.
  const uint32_t module[] = {0x07230203, 0x00010500, 0, 10, 0, (6u << 16) | 16u, 1, 17, 32, 4, 1};
  EXPECT_EQ(spirv_workgroup_size({module, sizeof module, "m"}),
            (std::array<uint32_t, 3>{32, 4, 1}));
  const uint32_t no_mode[] = {0x07230203, 0x00010500, 0, 10, 0};
  EXPECT_THROW(spirv_workgroup_size({no_mode, sizeof no_mode, "none"}), VulkanError);
  const uint32_t not_spirv[] = {1, 2, 3, 4, 5, 6};
  EXPECT_THROW(spirv_workgroup_size({not_spirv, sizeof not_spirv, "junk"}), VulkanError);
}

class DispatchTest : public VulkanTest {
 protected:
  // Runs iota over `n` elements of a buffer with kPad more, prefilled with kSentinel.
  std::vector<uint32_t> run_iota(Context& ctx, uint32_t n, uint32_t base) {
    const CoreKernels kernels(ctx);
    const Buffer dst(ctx, (uint64_t{n} + kPad) * sizeof(uint32_t), MemoryIntent::Device, "iota");
    Recorder rec(ctx, "iota");
    rec.fill(dst, kSentinel);
    rec.barrier();
    dispatch(rec, kernels.iota, layout::IotaPush{n, base}, {dst}, n);
    rec.submit_and_wait();
    return download<uint32_t>(ctx, dst, size_t{n} + kPad);
  }

  void expect_iota(const std::vector<uint32_t>& out, uint32_t n, uint32_t base) {
    ASSERT_EQ(out.size(), size_t{n} + kPad);
    uint32_t wrong = 0;
    for (uint32_t i = 0; i < n; ++i) wrong += out[i] != base + i ? 1 : 0;
    EXPECT_EQ(wrong, 0u) << "of " << n << " elements not written with their index";
    for (uint32_t i = n; i < n + kPad; ++i) {
      ASSERT_EQ(out[i], kSentinel) << "written beyond the end at " << i << " (n = " << n << ")";
    }
  }
};

TEST_F(DispatchTest, EveryElementWrittenNoneBeyond) {
  EXPECT_EQ(CoreKernels(ctx()).iota.workgroup_size(),
            (std::array<uint32_t, 3>{PHYXEL_WORKGROUP_SIZE, 1, 1}));
  for (const uint32_t n : {1u, 13u, 63u, 64u, 65u, 127u, 1000u}) {
    SCOPED_TRACE(n);
    expect_iota(run_iota(ctx(), n, 7), n, 7);
  }
}

// An iota dispatch into `dst` on the compute queue, then `copy`'s copy of it into `host`
// (Readback) waiting on a semaphore the dispatch signals, twice (the semaphore and both
// recorders reused): the copy holds the dispatch's values.
void expect_copy_after_dispatch(Context& c, Recorder& copy, const Buffer& dst, const Buffer& host) {
  const CoreKernels kernels(c);
  const auto n = static_cast<uint32_t>(dst.size() / sizeof(uint32_t));
  VkSemaphore written = VK_NULL_HANDLE;
  auto info = vk_struct<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
  VK_CHECK(c.fn().vkCreateSemaphore(c.device(), &info, nullptr, &written));
  {
    Recorder rec(c, "iota");
    for (uint32_t base : {5u, 9u}) {
      dispatch(rec, kernels.iota, layout::IotaPush{n, base}, {dst}, n);
      copy.copy(dst, host);
      rec.submit(VK_NULL_HANDLE, written);
      copy.submit(written);
      rec.wait();
      copy.wait();
      host.invalidate();
      const auto* got = static_cast<const uint32_t*>(host.mapped());
      uint32_t wrong = 0;
      for (uint32_t i = 0; i < n; ++i) wrong += got[i] != base + i ? 1 : 0;
      EXPECT_EQ(wrong, 0u) << base;
    }
  }
  c.fn().vkDestroySemaphore(c.device(), written, nullptr);
}

// A copy on the transfer-only queue of what a dispatch on the compute queue wrote, ordered by
// a semaphore (what FrameQueue does with a frame): the copy holds the dispatch's values. Where
// the device has no such queue (lavapipe), none is opened and a transfer Recorder is refused.
TEST_F(DispatchTest, TransferQueueCopiesWhatTheComputeQueueWrote) {
  Context& c = ctx();
  ContextOptions without = test_context_options();
  without.transfer_queue = false;
  EXPECT_EQ(make_context(without).transfer_queue(), VK_NULL_HANDLE);
  if (c.info().transfer_queue_family == UINT32_MAX) {
    EXPECT_EQ(c.transfer_queue(), VK_NULL_HANDLE);
    EXPECT_EQ(c.transfer_queue_family(), UINT32_MAX);
    try {
      Recorder copy(c, "copy", QueueRole::Transfer);
      ADD_FAILURE() << "a transfer Recorder without a transfer queue";
    } catch (const std::logic_error& e) {
      EXPECT_NE(std::string(e.what()).find("has no transfer queue open"), std::string::npos)
          << e.what();
    }
    return;
  }
  ASSERT_NE(c.transfer_queue(), VK_NULL_HANDLE);
  const uint32_t n = 1 << 20;
  const Buffer dst(c, n * sizeof(uint32_t), MemoryIntent::Device, "iota", 0,
                   /*with_transfer_queue=*/true);
  const Buffer host(c, n * sizeof(uint32_t), MemoryIntent::Readback, "iota read-back", 0,
                    /*with_transfer_queue=*/true);
  Recorder copy(c, "iota copy", QueueRole::Transfer);
  expect_copy_after_dispatch(c, copy, dst, host);
}

// A copy on the frame queue (a second queue of the compute family where it has several; the
// compute queue otherwise, as on lavapipe) of what a dispatch on the compute queue wrote,
// ordered by a semaphore (FrameQueue's deform pass and drawing): it holds the dispatch's values.
TEST_F(DispatchTest, FrameQueueReadsWhatTheComputeQueueWrote) {
  Context& c = ctx();
  ContextOptions without = test_context_options();
  without.frame_queue = false;
  EXPECT_EQ(make_context(without).frame_queue(), VK_NULL_HANDLE);
  EXPECT_EQ(c.frame_queue() != VK_NULL_HANDLE, c.info().compute_queue_count >= 2);
  const uint32_t n = 1 << 16;
  const Buffer values(c, n * sizeof(uint32_t), MemoryIntent::Device, "iota");
  const Buffer host(c, n * sizeof(uint32_t), MemoryIntent::Readback, "iota read-back");
  Recorder frame(c, "iota frame copy", QueueRole::Frame);
  expect_copy_after_dispatch(c, frame, values, host);
}

TEST_F(DispatchTest, DescriptorSetPathWithoutPushDescriptors) {
  ContextOptions options = test_context_options();
  options.push_descriptors = false;
  options.descriptor_cache = false;  // a set written per dispatch
  Context& plain = make_context(options);
  ASSERT_FALSE(plain.push_descriptors());
  ASSERT_FALSE(plain.pushes_descriptors());
  for (const uint32_t n : {1u, 13u, 127u, 1000u}) {
    SCOPED_TRACE(n);
    expect_iota(run_iota(plain, n, 3), n, 3);
  }
}

TEST_F(DispatchTest, MoreGroupsThanTheXLimitSpillIntoY) {
  // Lavapipe (and most GPUs) allow 65535 groups in x: 4.2 M invocations, 16 MiB of output.
  // NVIDIA allows 2^31 - 1, which no buffer could hold; group_counts is tested for it above.
  const uint64_t n = uint64_t{ctx().info().max_workgroup_count[0]} * PHYXEL_WORKGROUP_SIZE + 13;
  if (n > (uint64_t{1} << 26)) GTEST_SKIP() << "maxComputeWorkGroupCount[0] too large to fill";
  expect_iota(run_iota(ctx(), static_cast<uint32_t>(n), 0), static_cast<uint32_t>(n), 0);
}

TEST_F(DispatchTest, ManyDispatchesWithBarriersInOneSubmit) {
  const CoreKernels kernels(ctx());
  const uint32_t n = 1000;
  std::vector<float> x(n), y(n);
  for (uint32_t i = 0; i < n; ++i) {
    x[i] = static_cast<float>(i % 17) - 8.0f;
    y[i] = static_cast<float>(i) * 0.25f;
  }
  const Buffer bx(ctx(), n * sizeof(float), MemoryIntent::Device, "x");
  const Buffer by(ctx(), n * sizeof(float), MemoryIntent::Device, "y");
  upload(ctx(), bx, x);
  upload(ctx(), by, y);
  Recorder rec(ctx(), "axpy");
  for (int round = 0; round < 2; ++round) {  // the recorder is reused after a wait
    for (int i = 0; i < 3; ++i) {
      dispatch(rec, kernels.axpy, layout::AxpyPush{2.0f, n}, {bx, by}, n);
      rec.barrier();
    }
    EXPECT_EQ(rec.dispatch_count(), 3u);
    rec.submit_and_wait();
  }
  const std::vector<float> out = download<float>(ctx(), by, n);
  for (uint32_t i = 0; i < n; ++i) {
    ASSERT_EQ(out[i], y[i] + 12.0f * x[i]) << i;  // exact: small integers and quarters
  }
}

TEST_F(DispatchTest, BindingsAtAnOffset) {
  const CoreKernels kernels(ctx());
  const uint64_t align = ctx().info().min_storage_buffer_offset_alignment;
  const uint32_t skip = static_cast<uint32_t>(std::max<uint64_t>(align, 4) / 4);
  const uint32_t n = 13;
  const Buffer dst(ctx(), (skip + n + kPad) * sizeof(uint32_t), MemoryIntent::Device, "offset");
  Recorder rec(ctx(), "offset");
  rec.fill(dst, kSentinel);
  rec.barrier();
  dispatch(rec, kernels.iota, layout::IotaPush{n, 100}, {BufferRef(dst, skip * 4)}, n);
  rec.submit_and_wait();
  const std::vector<uint32_t> out = download<uint32_t>(ctx(), dst, skip + n + kPad);
  for (uint32_t i = 0; i < skip; ++i) EXPECT_EQ(out[i], kSentinel);
  expect_iota(std::vector<uint32_t>(out.begin() + skip, out.end()), n, 100);
}

TEST_F(DispatchTest, PushConstantSizeMustMatchThePipeline) {
  const CoreKernels kernels(ctx());
  ASSERT_EQ(kernels.iota.push_constant_size(), sizeof(layout::IotaPush));
  const Buffer dst(ctx(), 64 * sizeof(uint32_t), MemoryIntent::Device, "dst");
  Recorder rec(ctx(), "checks");
  struct TooBig {
    uint32_t count, base, extra, more;
  };
  try {
    dispatch(rec, kernels.iota, TooBig{64, 0, 0, 0}, {dst}, 64);
    FAIL() << "a 16-byte push for an 8-byte pipeline was accepted";
  } catch (const std::logic_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("'iota'"), std::string::npos) << message;
    EXPECT_NE(message.find("16 bytes"), std::string::npos) << message;
    EXPECT_NE(message.find("declares 8"), std::string::npos) << message;
  }
  EXPECT_THROW(dispatch(rec, kernels.iota, NoPush{}, {dst}, 64), std::logic_error);
  EXPECT_EQ(rec.dispatch_count(), 0u);
}

TEST_F(DispatchTest, BindingsMustMatchThePipeline) {
  const CoreKernels kernels(ctx());
  const Buffer a(ctx(), 64 * sizeof(float), MemoryIntent::Device, "a");
  const Buffer empty;
  Recorder rec(ctx(), "checks");
  const layout::AxpyPush push{1.0f, 64};
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {a}, 64), std::logic_error);
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {a, a, a}, 64), std::logic_error);
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {a, empty}, 64), std::logic_error);
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {a, BufferRef(a, 0, 65 * sizeof(float))}, 64),
               std::logic_error);
  rec.submit();
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {a, a}, 64), std::logic_error);
  rec.wait();
}

TEST_F(DispatchTest, TwoContextsAtOnce) {
  Context& second = make_context();
  const CoreKernels k1(ctx());
  const CoreKernels k2(second);
  expect_iota(run_iota(second, 127, 5), 127, 5);
  expect_iota(run_iota(ctx(), 13, 9), 13, 9);
}

}  // namespace
}  // namespace phyxel::gpu
