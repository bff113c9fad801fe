// Buffers by intent: memory-type choice, upload/download round trips on awkward sizes, the
// allocation counter and check_fits.
#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>
#include <vector>

#include "compute/buffer.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

constexpr VkMemoryPropertyFlags kLocal = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
constexpr VkMemoryPropertyFlags kVisible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
constexpr VkMemoryPropertyFlags kCoherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
constexpr VkMemoryPropertyFlags kCached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;

// A typical discrete GPU: VRAM, write-combined system memory, cached system memory, BAR.
VkPhysicalDeviceMemoryProperties discrete_memory() {
  VkPhysicalDeviceMemoryProperties m{};
  m.memoryHeapCount = 2;
  m.memoryHeaps[0] = {uint64_t{16} << 30, VK_MEMORY_HEAP_DEVICE_LOCAL_BIT};
  m.memoryHeaps[1] = {uint64_t{32} << 30, 0};
  m.memoryTypeCount = 4;
  m.memoryTypes[0] = {kVisible | kCoherent | kLocal, 0};  // BAR window first, to be avoided
  m.memoryTypes[1] = {kLocal, 0};
  m.memoryTypes[2] = {kVisible | kCoherent, 1};
  m.memoryTypes[3] = {kVisible | kCoherent | kCached, 1};
  return m;
}

TEST(MemoryType, ChosenByIntent) {
  const VkPhysicalDeviceMemoryProperties m = discrete_memory();
  EXPECT_EQ(choose_memory_type(m, 0xf, MemoryIntent::Device), 1u);
  EXPECT_EQ(choose_memory_type(m, 0xf, MemoryIntent::Upload), 2u);
  EXPECT_EQ(choose_memory_type(m, 0xf, MemoryIntent::Readback), 3u);
}

TEST(MemoryType, FallsBackWithinTheAllowedTypes) {
  const VkPhysicalDeviceMemoryProperties m = discrete_memory();
  EXPECT_EQ(choose_memory_type(m, 0x1, MemoryIntent::Device), 0u);    // only the BAR
  EXPECT_EQ(choose_memory_type(m, 0x1, MemoryIntent::Upload), 0u);    // ditto
  EXPECT_EQ(choose_memory_type(m, 0x4, MemoryIntent::Readback), 2u);  // uncached but visible
  EXPECT_EQ(choose_memory_type(m, 0x2, MemoryIntent::Upload), UINT32_MAX);
  EXPECT_EQ(choose_memory_type(m, 0x2, MemoryIntent::Readback), UINT32_MAX);
  EXPECT_EQ(choose_memory_type(m, 0x0, MemoryIntent::Device), UINT32_MAX);
}

class MemoryTest : public VulkanTest {};

TEST_F(MemoryTest, RoundTripOnAwkwardSizes) {
  for (const size_t n : {size_t{1}, size_t{13}, size_t{127}, size_t{1000}}) {
    for (const MemoryIntent intent :
         {MemoryIntent::Device, MemoryIntent::Upload, MemoryIntent::Readback}) {
      SCOPED_TRACE(std::string(intent_name(intent)) + " x" + std::to_string(n));
      std::vector<float> data(n);
      for (size_t i = 0; i < n; ++i) data[i] = 0.5f * static_cast<float>(i) - 3.25f;
      const Buffer buffer(ctx(), n * sizeof(float), intent, "round trip");
      EXPECT_EQ(buffer.size(), n * sizeof(float));
      EXPECT_EQ(buffer.mapped() != nullptr, intent != MemoryIntent::Device);
      upload(ctx(), buffer, data);
      EXPECT_EQ(download<float>(ctx(), buffer, n), data);
    }
  }
}

TEST_F(MemoryTest, PartialUploadAndDownloadAtOffsets) {
  const size_t n = 127;
  std::vector<uint32_t> data(n);
  std::iota(data.begin(), data.end(), 1000u);
  const Buffer buffer(ctx(), n * sizeof(uint32_t), MemoryIntent::Device, "partial");
  upload(ctx(), buffer, data);
  const std::vector<uint32_t> patch = {7, 8, 9};
  upload(ctx(), buffer, patch, 13 * sizeof(uint32_t));
  const std::vector<uint32_t> middle = download<uint32_t>(ctx(), buffer, 5, 12 * sizeof(uint32_t));
  EXPECT_EQ(middle, (std::vector<uint32_t>{1012, 7, 8, 9, 1016}));
  const std::vector<uint32_t> last = download<uint32_t>(ctx(), buffer, 1, 126 * sizeof(uint32_t));
  EXPECT_EQ(last, std::vector<uint32_t>{1126});
}

TEST_F(MemoryTest, OutOfRangeTransfersThrow) {
  const Buffer buffer(ctx(), 13 * sizeof(float), MemoryIntent::Device, "small");
  const std::vector<float> too_many(14, 1.0f);
  EXPECT_THROW(upload(ctx(), buffer, too_many), VulkanError);
  EXPECT_THROW(download<float>(ctx(), buffer, 2, 12 * sizeof(float)), VulkanError);
  EXPECT_THROW(upload(ctx(), Buffer(), too_many), VulkanError);
}

TEST_F(MemoryTest, EmptyBufferIsAllowed) {
  const Buffer empty(ctx(), 0, MemoryIntent::Device, "empty");
  EXPECT_TRUE(empty);
  EXPECT_EQ(empty.size(), 0u);
  EXPECT_TRUE(download<float>(ctx(), empty, 0).empty());
}

TEST_F(MemoryTest, AllocationCounterFollowsBuffers) {
  const uint64_t before = ctx().allocated_bytes();
  {
    Buffer a(ctx(), 1000 * sizeof(float), MemoryIntent::Device, "a");
    const Buffer b(ctx(), 13, MemoryIntent::Readback, "b");
    EXPECT_GE(ctx().allocated_bytes(), before + 1000 * sizeof(float) + 13);
    Buffer moved = std::move(a);
    EXPECT_FALSE(a);  // NOLINT(bugprone-use-after-move): moved-from is empty by contract
    EXPECT_GE(ctx().allocated_bytes(), before + 1000 * sizeof(float) + 13);
    moved.reset();
    EXPECT_LT(ctx().allocated_bytes(), before + 1000 * sizeof(float));
  }
  EXPECT_EQ(ctx().allocated_bytes(), before);
}

TEST_F(MemoryTest, CheckFitsRefusesAnImpossibleSize) {
  const uint64_t impossible = uint64_t{1} << 50;  // 1 PiB
  EXPECT_NO_THROW(ctx().check_fits(1 << 20));
  EXPECT_GT(ctx().available_device_memory(), uint64_t{1} << 20);
  try {
    ctx().check_fits(impossible);
    FAIL() << "1 PiB fits?";
  } catch (const VulkanError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
    EXPECT_NE(message.find("needs 1048576.0 GiB (" + std::to_string(impossible) + " bytes)"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find(" bytes) available"), std::string::npos) << message;
    EXPECT_NE(message.find("--device cpu"), std::string::npos) << message;
  }
  const uint64_t before = ctx().allocated_bytes();
  EXPECT_THROW(Buffer(ctx(), impossible, MemoryIntent::Device, "impossible"), VulkanError);
  EXPECT_EQ(ctx().allocated_bytes(), before);
}

}  // namespace
}  // namespace phyxel::gpu
