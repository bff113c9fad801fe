// Device enumeration and the --device rule: the pure selection logic on made-up device lists,
// then the real instance (lavapipe unless PHYXEL_TEST_DEVICE says otherwise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "compute/context.h"
#include "tests/support/support.h"
#include "vulkan_test.h"

namespace phyxel::gpu {
namespace {

DeviceInfo fake(uint32_t index, const std::string& name, VkPhysicalDeviceType type,
                uint32_t api = VK_API_VERSION_1_3) {
  DeviceInfo d;
  d.index = index;
  d.name = name;
  d.type = type;
  d.api_version = api;
  d.compute_queue_family = 0;
  return d;
}

std::vector<DeviceInfo> mixed_devices() {
  return {fake(0, "llvmpipe (LLVM 15.0.6, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU),
          fake(1, "Intel(R) UHD Graphics 630", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU),
          fake(2, "Virtio-GPU Venus", VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU),
          fake(3, "NVIDIA H100 80GB HBM3", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)};
}

std::string select_error(const std::vector<DeviceInfo>& devices, const std::string& spec) {
  return test::error_of<VulkanError>([&] { select_device(devices, spec); });
}

TEST(SelectDevice, GpuPrefersDiscreteThenIntegratedThenVirtualThenCpu) {
  std::vector<DeviceInfo> devices = mixed_devices();
  EXPECT_EQ(select_device(devices, "gpu"), 3u);
  EXPECT_EQ(select_device(devices, ""), 3u);
  devices.pop_back();
  EXPECT_EQ(select_device(devices, "gpu"), 1u);
  devices.erase(devices.begin() + 1);  // CPU, virtual
  EXPECT_EQ(select_device(devices, "gpu"), devices[1].index);
  devices.pop_back();
  EXPECT_EQ(select_device(devices, "gpu"), 0u);
}

TEST(SelectDevice, GpuSkipsDevicesBelowVulkan12) {
  std::vector<DeviceInfo> devices = mixed_devices();
  devices[3].api_version = VK_API_VERSION_1_1;
  EXPECT_EQ(select_device(devices, "gpu"), 1u);
  EXPECT_NE(select_error(devices, "gpu:3").find("unusable"), std::string::npos);
}

TEST(SelectDevice, IndexPicksThatDevice) {
  const std::vector<DeviceInfo> devices = mixed_devices();
  for (uint32_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(select_device(devices, "gpu:" + std::to_string(i)), i);
  }
}

TEST(SelectDevice, BadIndexListsTheDevices) {
  const std::vector<DeviceInfo> devices = mixed_devices();
  for (const std::string spec : {"gpu:4", "gpu:", "gpu:x", "gpu:-1", "gpu:99999999999"}) {
    const std::string message = select_error(devices, spec);
    for (const DeviceInfo& d : devices) {
      EXPECT_NE(message.find(d.name), std::string::npos) << spec << ": " << message;
    }
  }
}

TEST(SelectDevice, NameIsACaseInsensitiveSubstring) {
  const std::vector<DeviceInfo> devices = mixed_devices();
  EXPECT_EQ(select_device(devices, "h100"), 3u);
  EXPECT_EQ(select_device(devices, "NVIDIA"), 3u);
  EXPECT_EQ(select_device(devices, "uhd graphics"), 1u);
  EXPECT_EQ(select_device(devices, "LLVMPIPE"), 0u);
}

TEST(SelectDevice, UnknownNameListsTheDevices) {
  const std::vector<DeviceInfo> devices = mixed_devices();
  const std::string message = select_error(devices, "radeon");
  EXPECT_NE(message.find("'radeon'"), std::string::npos) << message;
  for (const DeviceInfo& d : devices) {
    EXPECT_NE(message.find(d.name), std::string::npos) << message;
  }
}

TEST(SelectDevice, NoDeviceIsOneLineSuggestingCpu) {
  const std::string message = select_error({}, "gpu");
  EXPECT_NE(message.find("no Vulkan device"), std::string::npos) << message;
  EXPECT_NE(message.find("--device cpu"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

TEST(SelectDevice, CpuIsTheReferenceSolverNotADevice) {
  const std::string message = select_error(mixed_devices(), "cpu");
  EXPECT_NE(message.find("CPU reference solver"), std::string::npos) << message;
}

class DeviceTest : public VulkanTest {};

TEST_F(DeviceTest, EnumeratesDevicesWithSaneLimits) {
  const std::vector<DeviceInfo>& devices = ctx().instance().devices();
  ASSERT_FALSE(devices.empty());
  for (const DeviceInfo& d : devices) {
    EXPECT_FALSE(d.name.empty());
    EXPECT_GE(d.api_version, VK_API_VERSION_1_2) << d.name;
    // Vulkan's required minimums.
    EXPECT_GE(d.max_workgroup_invocations, 128u) << d.name;
    EXPECT_GE(d.max_workgroup_size[0], 128u) << d.name;
    EXPECT_GE(d.max_workgroup_count[0], 65535u) << d.name;
    EXPECT_GE(d.max_push_constants_size, 128u) << d.name;
    EXPECT_GE(d.max_storage_buffer_range, uint32_t{1} << 27) << d.name;
    EXPECT_GT(d.subgroup_size, 0u) << d.name;
    EXPECT_GT(d.device_local_bytes, 0u) << d.name;
  }
  if (std::getenv("PHYXEL_TEST_DEVICE") == nullptr) {
    ASSERT_EQ(devices.size(), 1u) << "VK_DRIVER_FILES should leave only lavapipe";
    EXPECT_EQ(devices[0].type, VK_PHYSICAL_DEVICE_TYPE_CPU);
    EXPECT_NE(devices[0].name.find("llvmpipe"), std::string::npos);
    EXPECT_TRUE(devices[0].push_descriptor);
    EXPECT_TRUE(devices[0].timestamps());
  }
  EXPECT_TRUE(ctx().instance().validation() || std::getenv("PHYXEL_TEST_VALIDATION") != nullptr);
}

TEST_F(DeviceTest, SelectsByIndexAndByName) {
  const std::vector<DeviceInfo>& devices = ctx().instance().devices();
  const DeviceInfo& last = devices.back();
  ContextOptions options = test_context_options();
  options.device = "gpu:" + std::to_string(last.index);
  EXPECT_EQ(make_context(options).info().index, last.index);

  std::string upper = last.name.substr(0, std::min<size_t>(last.name.size(), 6));
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  options.device = upper;
  EXPECT_NE(make_context(options).info().name.find(last.name.substr(0, upper.size())),
            std::string::npos);
}

TEST_F(DeviceTest, BadNameErrorListsTheRealDevices) {
  ContextOptions options = test_context_options();
  options.device = "no-such-device-xyz";
  try {
    Context unused(options);
    FAIL() << "a device named no-such-device-xyz was found";
  } catch (const VulkanError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("no-such-device-xyz"), std::string::npos) << message;
    for (const DeviceInfo& d : ctx().instance().devices()) {
      EXPECT_NE(message.find(d.name), std::string::npos) << message;
    }
  }
}

TEST_F(DeviceTest, ContextRecordsWhatItEnabled) {
  const DeviceInfo& info = ctx().info();
  EXPECT_EQ(ctx().push_descriptors(), info.push_descriptor);
  EXPECT_EQ(ctx().float64(), info.float64);
  EXPECT_EQ(ctx().timestamps(), info.timestamps());
  EXPECT_NE(ctx().queue(), VK_NULL_HANDLE);
  EXPECT_NE(ctx().fn().vkCmdDispatch, nullptr);
  if (std::getenv("PHYXEL_TEST_DEVICE") == nullptr) {
    EXPECT_TRUE(ctx().float64()) << "lavapipe supports shaderFloat64";
  }
  ContextOptions options = test_context_options();
  options.push_descriptors = false;
  EXPECT_FALSE(make_context(options).push_descriptors());
}

}  // namespace
}  // namespace phyxel::gpu
