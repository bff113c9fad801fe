// The Recorder's cached descriptor sets (ContextOptions::descriptor_cache): a binding list met
// again binds the set written the first time, across submissions; a recreated buffer (whose
// VkBuffer handle value may be the old one's), another offset or range, or another pipeline
// gets its own; the cache is dropped after a wait once it holds too many; block names are still
// checked; and the results are those of the push-descriptor path. Buffer and Pipeline serials.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "compute/kernels.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

class DescriptorCacheTest : public VulkanTest {
 protected:
  // A context with the cache on, whatever $PHYXEL_DESCRIPTOR_CACHE says.
  Context& cached() {
    ContextOptions options = test_context_options();
    options.descriptor_cache = true;
    return make_context(options);
  }
};

std::vector<uint32_t> iota_values(uint32_t n, uint32_t base) {
  std::vector<uint32_t> out(n);
  for (uint32_t i = 0; i < n; ++i) out[i] = base + i;
  return out;
}

TEST_F(DescriptorCacheTest, SerialsAreUniqueAndMoveWithTheBuffer) {
  Context& c = ctx();
  Buffer a(c, 64, MemoryIntent::Device, "a");
  const Buffer b(c, 64, MemoryIntent::Device, "b");
  EXPECT_NE(a.serial(), 0u);
  EXPECT_NE(a.serial(), b.serial());
  const uint64_t serial = a.serial();
  Buffer moved(std::move(a));
  EXPECT_EQ(moved.serial(), serial);
  EXPECT_EQ(a.serial(), 0u);  // NOLINT(bugprone-use-after-move): moved-from is empty
  moved.reset();
  EXPECT_EQ(moved.serial(), 0u);
  // A buffer made after one is destroyed gets a new serial, even where Vulkan hands out the
  // same handle value again.
  std::set<uint64_t> serials;
  for (int i = 0; i < 8; ++i) serials.insert(Buffer(c, 64, MemoryIntent::Device, "x").serial());
  EXPECT_EQ(serials.size(), 8u);
  const CoreKernels k1(c), k2(c);
  EXPECT_NE(k1.iota.serial(), 0u);
  EXPECT_NE(k1.iota.serial(), k2.iota.serial());
  EXPECT_EQ(Pipeline().serial(), 0u);
}

TEST_F(DescriptorCacheTest, AListMetAgainBindsTheSameSetAcrossSubmissions) {
  Context& c = cached();
  const CoreKernels kernels(c);
  const uint32_t n = 100;
  const Buffer dst(c, n * sizeof(uint32_t), MemoryIntent::Device, "dst");
  Recorder rec(c, "cache");
  dispatch(rec, kernels.iota, layout::IotaPush{n, 1}, {dst}, n);
  ASSERT_EQ(rec.descriptor_cache().size(), 1u);
  rec.barrier();
  dispatch(rec, kernels.iota, layout::IotaPush{n, 2}, {dst}, n);
  EXPECT_EQ(rec.descriptor_cache().size(), 1u);
  rec.submit_and_wait();
  EXPECT_EQ(download<uint32_t>(c, dst, n), iota_values(n, 2));
  dispatch(rec, kernels.iota, layout::IotaPush{n, 3}, {dst}, n);
  EXPECT_EQ(rec.descriptor_cache().size(), 1u);  // kept across the wait
  rec.submit_and_wait();
  EXPECT_EQ(download<uint32_t>(c, dst, n), iota_values(n, 3));
  // Another pipeline with the same buffers has its own set.
  dispatch(rec, kernels.axpy, layout::AxpyPush{1.0f, 0}, {dst, dst}, 0);
  EXPECT_EQ(rec.descriptor_cache().size(), 2u);
}

TEST_F(DescriptorCacheTest, ARecreatedBufferGetsANewSet) {
  Context& c = cached();
  const CoreKernels kernels(c);
  const uint32_t n = 64;
  Recorder rec(c, "cache");
  Buffer dst(c, n * sizeof(uint32_t), MemoryIntent::Device, "dst");
  dispatch(rec, kernels.iota, layout::IotaPush{n, 10}, {dst}, n);
  rec.submit_and_wait();
  ASSERT_EQ(rec.descriptor_cache().size(), 1u);
  for (uint32_t round = 0; round < 4; ++round) {
    dst = Buffer(c, n * sizeof(uint32_t), MemoryIntent::Device, "dst");  // old one destroyed
    dispatch(rec, kernels.iota, layout::IotaPush{n, 20 + round}, {dst}, n);
    rec.submit_and_wait();
    EXPECT_EQ(rec.descriptor_cache().size(), 2u + round);
    EXPECT_EQ(download<uint32_t>(c, dst, n), iota_values(n, 20 + round)) << round;
  }
}

TEST_F(DescriptorCacheTest, AnotherOffsetOrRangeMisses) {
  Context& c = cached();
  const CoreKernels kernels(c);
  const uint64_t align = std::max<uint64_t>(c.info().min_storage_buffer_offset_alignment, 4);
  const uint32_t skip = static_cast<uint32_t>(align / 4);
  const uint32_t n = 8;
  const Buffer dst(c, (2 * skip + n) * sizeof(uint32_t), MemoryIntent::Device, "dst");
  Recorder rec(c, "cache");
  rec.fill(dst, 0);
  rec.barrier();
  dispatch(rec, kernels.iota, layout::IotaPush{n, 100}, {BufferRef(dst, 0, n * 4)}, n);
  rec.barrier();
  dispatch(rec, kernels.iota, layout::IotaPush{n, 200}, {BufferRef(dst, align, n * 4)}, n);
  rec.barrier();
  EXPECT_EQ(rec.descriptor_cache().size(), 2u);
  dispatch(rec, kernels.iota, layout::IotaPush{n, 300}, {BufferRef(dst, 2 * align, n * 4)}, n);
  EXPECT_EQ(rec.descriptor_cache().size(), 3u);
  rec.barrier();
  // The first offset again with a range of one element: only element 0 is written.
  dispatch(rec, kernels.iota, layout::IotaPush{1, 400}, {BufferRef(dst, 0, 4)}, 1);
  EXPECT_EQ(rec.descriptor_cache().size(), 4u);
  rec.submit_and_wait();
  const std::vector<uint32_t> out = download<uint32_t>(c, dst, 2 * skip + n);
  EXPECT_EQ(out[0], 400u);
  for (uint32_t i = 1; i < skip; ++i) EXPECT_EQ(out[i], 100u + i) << i;
  for (uint32_t i = 0; i < n; ++i) EXPECT_EQ(out[2 * skip + i], 300u + i) << i;
}

TEST_F(DescriptorCacheTest, DroppedAfterAWaitOnceItHoldsTooMany) {
  Context& c = cached();
  const CoreKernels kernels(c);
  const uint64_t align = std::max<uint64_t>(c.info().min_storage_buffer_offset_alignment, 4);
  const size_t lists = Recorder::kCachedSets + 1;
  const Buffer dst(c, lists * align, MemoryIntent::Device, "dst");
  Recorder rec(c, "cache");
  // No invocations: nothing recorded, but each list is checked and its set kept.
  for (size_t k = 0; k < lists; ++k)
    dispatch(rec, kernels.iota, layout::IotaPush{0, 0}, {BufferRef(dst, k * align, 4)}, 0);
  EXPECT_EQ(rec.descriptor_cache().size(), lists);
  rec.submit_and_wait();
  EXPECT_EQ(rec.descriptor_cache().size(), 0u);
  dispatch(rec, kernels.iota, layout::IotaPush{4, 7}, {BufferRef(dst, 0, 16)}, 4);
  rec.submit_and_wait();
  EXPECT_EQ(download<uint32_t>(c, dst, 4), iota_values(4, 7));
}

TEST_F(DescriptorCacheTest, BlockNamesAreCheckedOnAHit) {
  Context& c = cached();
  const CoreKernels kernels(c);
  const Buffer x(c, 64, MemoryIntent::Device, "x");
  const Buffer y(c, 64, MemoryIntent::Device, "y");
  Recorder rec(c, "cache");
  const layout::AxpyPush push{1.0f, 0};
  dispatch(rec, kernels.axpy, push, {{"X", x}, {"Y", y}}, 0);
  // The same buffers at the same bindings, named wrongly or partly: refused though cached.
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {{"Y", x}, {"X", y}}, 0), std::logic_error);
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {{"X", x}, y}, 0), std::logic_error);
  EXPECT_THROW(dispatch(rec, kernels.axpy, push, {x, {"Y", y}}, 0), std::logic_error);
  // Unnamed and named again (other pointers to the same names) are fine.
  dispatch(rec, kernels.axpy, push, {x, y}, 0);
  const std::string names[2] = {"X", "Y"};
  dispatch(rec, kernels.axpy, push, {{names[0].c_str(), x}, {names[1].c_str(), y}}, 0);
  EXPECT_EQ(rec.descriptor_cache().size(), 1u);
}

// axpy over the same buffers, three dispatches a submission, two submissions, with the cache, with
// push descriptors (where the device has them) and with a set written per dispatch: the same
// bits.
TEST_F(DescriptorCacheTest, ResultsAreThoseOfEveryDescriptorPath) {
  const uint32_t n = 777;
  std::vector<float> x(n), y(n);
  for (uint32_t i = 0; i < n; ++i) {
    x[i] = 0.37f * static_cast<float>(i % 29) - 3.1f;
    y[i] = 1.0f / static_cast<float>(i + 3);
  }
  std::vector<std::vector<float>> results;
  using Path = std::pair<bool, bool>;  // cache, push descriptors
  for (const auto& [cache, push] : {Path{true, true}, Path{false, true}, Path{false, false}}) {
    ContextOptions options = test_context_options();
    options.descriptor_cache = cache;
    options.push_descriptors = push;
    Context& c = make_context(options);
    const CoreKernels kernels(c);
    const Buffer bx(c, n * sizeof(float), MemoryIntent::Device, "x");
    const Buffer by(c, n * sizeof(float), MemoryIntent::Device, "y");
    upload(c, bx, x);
    upload(c, by, y);
    Recorder rec(c, "axpy");
    for (int round = 0; round < 2; ++round) {
      for (int i = 0; i < 3; ++i) {
        dispatch(rec, kernels.axpy, layout::AxpyPush{0.5f + float(i), n}, {bx, by}, n);
        rec.barrier();
      }
      rec.submit_and_wait();
    }
    EXPECT_EQ(rec.descriptor_cache().size(), cache ? 1u : 0u);
    results.push_back(download<float>(c, by, n));
  }
  EXPECT_EQ(results[0], results[1]);
  EXPECT_EQ(results[0], results[2]);
}

}  // namespace
}  // namespace phyxel::gpu
