// What Phyxel knows about one Vulkan physical device, and the `--device` choice among them.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "compute/vk_functions.h"

namespace phyxel::gpu {

struct DeviceInfo {
  uint32_t index = 0;  // position in vkEnumeratePhysicalDevices order ("gpu:N")
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::string driver_name;  // "llvmpipe", "NVIDIA", ... (empty below Vulkan 1.2)
  std::string driver_info;  // driver version text
  uint32_t api_version = 0;
  uint64_t device_local_bytes = 0;  // size of the largest device-local heap
  std::array<uint32_t, 3> max_workgroup_size{};
  uint32_t max_workgroup_invocations = 0;
  std::array<uint32_t, 3> max_workgroup_count{};
  uint32_t max_storage_buffer_range = 0;
  uint32_t max_push_constants_size = 0;
  uint64_t max_allocation_size = 0;            // maxMemoryAllocationSize (0: unknown)
  uint32_t subgroup_size = 0;                  // reported, never assumed (lavapipe's is 8)
  uint32_t compute_queue_family = UINT32_MAX;  // UINT32_MAX: no compute queue
  uint32_t compute_queue_count = 0;            // queues of that family
  uint32_t timestamp_valid_bits = 0;           // of the compute queue family; 0: no timestamps
  // A family of transfer queues alone (a GPU's copy engines), UINT32_MAX where there is none
  // (lavapipe has one family for everything).
  uint32_t transfer_queue_family = UINT32_MAX;
  float timestamp_period_ns = 0;
  uint64_t min_storage_buffer_offset_alignment = 0;
  uint32_t max_push_descriptors = 0;  // 0 when VK_KHR_push_descriptor is absent
  bool float64 = false;               // shaderFloat64
  bool int64 = false;                 // shaderInt64
  bool int64_atomics = false;         // and shaderBufferInt64Atomics (core in Vulkan 1.2)
  bool push_descriptor = false;       // VK_KHR_push_descriptor
  bool memory_budget = false;         // VK_EXT_memory_budget
  bool portability_subset = false;    // VK_KHR_portability_subset (must then be enabled)

  bool timestamps() const { return timestamp_valid_bits > 0 && timestamp_period_ns > 0; }
  // Why Phyxel cannot run on it ("" when it can): Vulkan below 1.2, or no compute queue.
  std::string unusable_reason() const;
};

// Fills a DeviceInfo (device extensions, limits, features, queues, heaps).
DeviceInfo query_device_info(const InstanceFunctions& fn, VkPhysicalDevice device, uint32_t index);

// "discrete GPU", "integrated GPU", "virtual GPU", "CPU", "other".
const char* device_type_name(VkPhysicalDeviceType type);
// "1.3.230".
std::string api_version_string(uint32_t version);
// One line per device: "  0: llvmpipe (LLVM 15.0.6, 256 bits) [CPU, llvmpipe, Vulkan 1.3.230]".
std::string describe_devices(const std::vector<DeviceInfo>& devices);

// The `--device` rule. `spec`:
//   "gpu" (or "")  the best usable device: discrete > integrated > virtual > CPU driver
//                  (lavapipe) > other; among equals the lowest index
//   "gpu:N"        device N
//   anything else  the best usable device whose name contains `spec`, ignoring case
// Returns the chosen index; throws VulkanError naming the available devices when nothing fits.
uint32_t select_device(const std::vector<DeviceInfo>& devices, const std::string& spec);

}  // namespace phyxel::gpu
