#include "compute/device_info.h"

#include <algorithm>
#include <cctype>
#include <cstring>

namespace phyxel::gpu {
namespace {

int type_rank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 1;
    default:
      return 0;
  }
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

[[noreturn]] void no_fit(const std::vector<DeviceInfo>& devices, const std::string& what) {
  throw VulkanError(what + "; available Vulkan devices:\n" + describe_devices(devices),
                    VK_ERROR_INITIALIZATION_FAILED);
}

// The best usable device among `candidates` (indices into `devices`); UINT32_MAX if none.
uint32_t best_of(const std::vector<DeviceInfo>& devices, const std::vector<uint32_t>& candidates) {
  uint32_t best = UINT32_MAX;
  for (uint32_t i : candidates) {
    if (!devices[i].unusable_reason().empty()) continue;
    if (best == UINT32_MAX || type_rank(devices[i].type) > type_rank(devices[best].type)) best = i;
  }
  return best;
}

}  // namespace

std::string DeviceInfo::unusable_reason() const {
  if (api_version < VK_API_VERSION_1_2) {
    return "Vulkan " + api_version_string(api_version) + ", Phyxel needs 1.2";
  }
  if (compute_queue_family == UINT32_MAX) return "no compute queue";
  return {};
}

DeviceInfo query_device_info(const InstanceFunctions& fn, VkPhysicalDevice device, uint32_t index) {
  DeviceInfo info;
  info.index = index;

  uint32_t count = 0;
  VK_CHECK(fn.vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr));
  std::vector<VkExtensionProperties> extensions(count);
  VK_CHECK(fn.vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data()));
  auto has = [&](const char* name) {
    return std::any_of(extensions.begin(), extensions.end(), [&](const VkExtensionProperties& e) {
      return std::strcmp(e.extensionName, name) == 0;
    });
  };
  info.push_descriptor = has(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  info.memory_budget = has(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
  info.portability_subset = has("VK_KHR_portability_subset");

  VkPhysicalDeviceProperties base{};
  fn.vkGetPhysicalDeviceProperties(device, &base);
  info.api_version = base.apiVersion;
  if (base.apiVersion >= VK_API_VERSION_1_2) {
    // The structures below are core in 1.1/1.2; older devices only get the base properties.
    auto driver = vk_struct<VkPhysicalDeviceDriverProperties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
    auto subgroup = vk_struct<VkPhysicalDeviceSubgroupProperties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES);
    auto maint3 = vk_struct<VkPhysicalDeviceMaintenance3Properties>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES);
    auto push = vk_struct<VkPhysicalDevicePushDescriptorPropertiesKHR>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PUSH_DESCRIPTOR_PROPERTIES_KHR);
    driver.pNext = &subgroup;
    subgroup.pNext = &maint3;
    if (info.push_descriptor) maint3.pNext = &push;
    auto props = vk_struct<VkPhysicalDeviceProperties2>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &driver);
    fn.vkGetPhysicalDeviceProperties2(device, &props);
    info.driver_name = driver.driverName;
    info.driver_info = driver.driverInfo;
    info.subgroup_size = subgroup.subgroupSize;
    info.max_allocation_size = maint3.maxMemoryAllocationSize;
    info.max_push_descriptors = info.push_descriptor ? push.maxPushDescriptors : 0;
  }
  info.name = base.deviceName;
  info.type = base.deviceType;
  const VkPhysicalDeviceLimits& limits = base.limits;
  for (int i = 0; i < 3; ++i) {
    info.max_workgroup_size[i] = limits.maxComputeWorkGroupSize[i];
    info.max_workgroup_count[i] = limits.maxComputeWorkGroupCount[i];
  }
  info.max_workgroup_invocations = limits.maxComputeWorkGroupInvocations;
  info.max_storage_buffer_range = limits.maxStorageBufferRange;
  info.max_push_constants_size = limits.maxPushConstantsSize;
  info.min_storage_buffer_offset_alignment = limits.minStorageBufferOffsetAlignment;
  info.timestamp_period_ns = limits.timestampPeriod;

  auto atomic64 = vk_struct<VkPhysicalDeviceShaderAtomicInt64Features>(
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES);
  // The Vulkan 1.2 struct only where 1.2 is there (else unusable anyway).
  auto features = vk_struct<VkPhysicalDeviceFeatures2>(
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
      base.apiVersion >= VK_API_VERSION_1_2 ? &atomic64 : nullptr);
  fn.vkGetPhysicalDeviceFeatures2(device, &features);
  info.float64 = features.features.shaderFloat64 == VK_TRUE;
  info.int64 = features.features.shaderInt64 == VK_TRUE;
  info.int64_atomics = info.int64 && atomic64.shaderBufferInt64Atomics == VK_TRUE;

  // Prefer a universal (graphics + compute) family: the renderer reads the solver's buffers
  // on the same queue, so no queue-family ownership transfers are needed.
  fn.vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  fn.vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  auto has_flag = [&](uint32_t family, VkQueueFlags flag) {
    return (families[family].queueFlags & flag) != 0 && families[family].queueCount > 0;
  };
  for (uint32_t i = 0; i < count; ++i) {
    if (has_flag(i, VK_QUEUE_TRANSFER_BIT) && !has_flag(i, VK_QUEUE_COMPUTE_BIT) &&
        !has_flag(i, VK_QUEUE_GRAPHICS_BIT) && info.transfer_queue_family == UINT32_MAX)
      info.transfer_queue_family = i;
    if (!has_flag(i, VK_QUEUE_COMPUTE_BIT)) continue;
    const uint32_t chosen = info.compute_queue_family;
    if (chosen == UINT32_MAX ||
        (has_flag(i, VK_QUEUE_GRAPHICS_BIT) && !has_flag(chosen, VK_QUEUE_GRAPHICS_BIT))) {
      info.compute_queue_family = i;
      info.compute_queue_count = families[i].queueCount;
      info.timestamp_valid_bits = families[i].timestampValidBits;
    }
  }

  VkPhysicalDeviceMemoryProperties memory{};
  fn.vkGetPhysicalDeviceMemoryProperties(device, &memory);
  for (uint32_t i = 0; i < memory.memoryHeapCount; ++i) {
    if ((memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0) {
      info.device_local_bytes =
          std::max<uint64_t>(info.device_local_bytes, memory.memoryHeaps[i].size);
    }
  }
  return info;
}

const char* device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

std::string api_version_string(uint32_t version) {
  return std::to_string(VK_API_VERSION_MAJOR(version)) + "." +
         std::to_string(VK_API_VERSION_MINOR(version)) + "." +
         std::to_string(VK_API_VERSION_PATCH(version));
}

std::string describe_devices(const std::vector<DeviceInfo>& devices) {
  if (devices.empty()) return "  (none)\n";
  std::string out;
  for (const DeviceInfo& d : devices) {
    out += "  " + std::to_string(d.index) + ": " + d.name + " [" + device_type_name(d.type);
    if (!d.driver_name.empty()) out += ", " + d.driver_name;
    out += ", Vulkan " + api_version_string(d.api_version) + "]";
    const std::string why = d.unusable_reason();
    if (!why.empty()) out += " unusable: " + why;
    out += "\n";
  }
  return out;
}

uint32_t select_device(const std::vector<DeviceInfo>& devices, const std::string& spec) {
  if (devices.empty()) {
    throw VulkanError(
        "no Vulkan device found: install a driver such as mesa-vulkan-drivers, or use "
        "--device cpu",
        VK_ERROR_INCOMPATIBLE_DRIVER);
  }
  if (spec == "cpu") {
    no_fit(devices,
           "'cpu' selects the CPU reference solver, not a Vulkan device (use 'gpu', 'gpu:N' "
           "or part of a device name)");
  }
  std::vector<uint32_t> candidates;
  if (spec.empty() || spec == "gpu") {
    for (const DeviceInfo& d : devices) candidates.push_back(d.index);
    const uint32_t best = best_of(devices, candidates);
    if (best == UINT32_MAX) no_fit(devices, "no usable Vulkan device (Phyxel needs Vulkan 1.2)");
    return best;
  }
  if (spec.rfind("gpu:", 0) == 0) {
    const std::string number = spec.substr(4);
    const bool digits = !number.empty() && number.size() < 10 &&
                        std::all_of(number.begin(), number.end(),
                                    [](unsigned char c) { return std::isdigit(c) != 0; });
    if (!digits) no_fit(devices, "bad device '" + spec + "': expected gpu:N with N a number");
    const uint32_t index = static_cast<uint32_t>(std::stoul(number));
    if (index >= devices.size()) no_fit(devices, "no Vulkan device " + number);
    const std::string why = devices[index].unusable_reason();
    if (!why.empty()) no_fit(devices, "Vulkan device " + number + " is unusable: " + why);
    return index;
  }
  const std::string needle = lower(spec);
  for (const DeviceInfo& d : devices) {
    if (lower(d.name).find(needle) != std::string::npos) candidates.push_back(d.index);
  }
  if (candidates.empty()) no_fit(devices, "no Vulkan device name contains '" + spec + "'");
  const uint32_t best = best_of(devices, candidates);
  if (best == UINT32_MAX) no_fit(devices, "no usable Vulkan device name contains '" + spec + "'");
  return best;
}

}  // namespace phyxel::gpu
