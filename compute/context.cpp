#include "compute/context.h"

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <optional>
#include <vector>

#include "compute/env.h"

namespace phyxel::gpu {

bool validation_default() {
  return PHYXEL_VALIDATION_DEFAULT != 0;
}

bool descriptor_cache_default() {
  return env_switch("PHYXEL_DESCRIPTOR_CACHE");
}

std::string format_bytes(uint64_t bytes) {
  char text[64];
  const double b = static_cast<double>(bytes);
  if (bytes >= (uint64_t{1} << 30)) {
    std::snprintf(text, sizeof text, "%.1f GiB", b / (1024.0 * 1024.0 * 1024.0));
  } else if (bytes >= (uint64_t{1} << 20)) {
    std::snprintf(text, sizeof text, "%.1f MiB", b / (1024.0 * 1024.0));
  } else if (bytes >= 1024) {
    std::snprintf(text, sizeof text, "%.1f KiB", b / 1024.0);
  } else {
    std::snprintf(text, sizeof text, "%" PRIu64 " B", bytes);
  }
  return text;
}

namespace {

// The context's environment (compute/env.h): a malformed value fails the context's creation
// as a VulkanError, as other setup failures do (one line from `phyxel run`).
template <class Read>
auto from_env(Read read) {
  try {
    return read();
  } catch (const EnvError& e) {
    throw VulkanError(e.what());
  }
}

// $PHYXEL_FRAME_QUEUE "0" turns ContextOptions::frame_queue off (to time frames drawn on the
// solver's queue against frames drawn beside it).
bool frame_queue_allowed() {
  return from_env([] { return env_switch("PHYXEL_FRAME_QUEUE"); });
}

// A test hook's count (context.h), counting `unit`; nullopt when unset.
std::optional<int64_t> test_hook(const char* name, const char* unit) {
  return from_env([&] { return env_number(name, 0, INT64_MAX, unit, "the hook off"); });
}

// How long a submission may run: $PHYXEL_GPU_TIMEOUT_S seconds where set, else the option's
// wait, at least 10 min on a CPU driver (lavapipe on a loaded machine is slow, not hung).
uint32_t fence_timeout_ms_for(const ContextOptions& options, const DeviceInfo& info) {
  const std::optional<int64_t> seconds = from_env([] {
    return env_number("PHYXEL_GPU_TIMEOUT_S", 1, 86400, "seconds",
                      "the default (120 on a GPU, 600 on a CPU driver)");
  });
  if (seconds) return static_cast<uint32_t>(*seconds * 1000);
  constexpr uint32_t kCpuDriverMs = 600000;
  if (info.type == VK_PHYSICAL_DEVICE_TYPE_CPU)
    return std::max(options.fence_timeout_ms, kCpuDriverMs);
  return options.fence_timeout_ms;
}

}  // namespace

void Context::set_test_fail_allocation_after(int64_t n) {
  test_fail_alloc_after_ = n < 0 ? UINT64_MAX : allocations_ + static_cast<uint64_t>(n);
}

Context::Context(const ContextOptions& options)
    : options_(options),
      instance_(
          std::make_unique<Instance>(InstanceOptions{options.validation, options.loader_path})) {
  const InstanceFunctions& ifn = instance_->fn();
  const uint32_t index = select_device(instance_->devices(), options.device);
  info_ = instance_->devices()[index];
  physical_ = instance_->physical_device(index);
  options_.fence_timeout_ms = fence_timeout_ms_for(options, info_);

  push_descriptors_ = info_.push_descriptor && options.push_descriptors;
  memory_budget_ = info_.memory_budget;
  std::vector<const char*> extensions;
  if (push_descriptors_) extensions.push_back(VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME);
  if (memory_budget_) extensions.push_back(VK_EXT_MEMORY_BUDGET_EXTENSION_NAME);
  if (info_.portability_subset) extensions.push_back("VK_KHR_portability_subset");

  auto features =
      vk_struct<VkPhysicalDeviceFeatures2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2);
  features.features.shaderFloat64 = info_.float64 ? VK_TRUE : VK_FALSE;
  features.features.shaderInt64 = info_.int64 ? VK_TRUE : VK_FALSE;
  auto atomic64 = vk_struct<VkPhysicalDeviceShaderAtomicInt64Features>(
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_ATOMIC_INT64_FEATURES);
  atomic64.shaderBufferInt64Atomics = info_.int64_atomics ? VK_TRUE : VK_FALSE;
  features.pNext = &atomic64;

  // The compute family's queues: the solver's, then the frame queue's.
  const float priorities[2] = {1.0f, 1.0f};
  const bool frame_queue =
      options.frame_queue && frame_queue_allowed() && info_.compute_queue_count >= 2;
  VkDeviceQueueCreateInfo queues[2];
  uint32_t queue_count = 0;
  for (const uint32_t family : {info_.compute_queue_family, info_.transfer_queue_family}) {
    if (family == UINT32_MAX || (queue_count > 0 && !options.transfer_queue)) continue;
    VkDeviceQueueCreateInfo& queue = queues[queue_count++];
    queue = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    queue.queueFamilyIndex = family;
    queue.queueCount = queue_count == 1 && frame_queue ? 2 : 1;
    queue.pQueuePriorities = priorities;
  }

  auto create = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  create.pNext = &features;
  create.queueCreateInfoCount = queue_count;
  create.pQueueCreateInfos = queues;
  create.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  create.ppEnabledExtensionNames = extensions.data();
  VK_CHECK(ifn.vkCreateDevice(physical_, &create, nullptr, &device_));
  try {
    fn_ = load_device_functions(ifn, device_);
    if (push_descriptors_ && fn_.vkCmdPushDescriptorSetKHR == nullptr) push_descriptors_ = false;
    fn_.vkGetDeviceQueue(device_, info_.compute_queue_family, 0, &queue_);
    if (queue_count == 2)
      fn_.vkGetDeviceQueue(device_, info_.transfer_queue_family, 0, &transfer_queue_);
    if (frame_queue) fn_.vkGetDeviceQueue(device_, info_.compute_queue_family, 1, &frame_queue_);

    ifn.vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
    VkDeviceSize largest = 0;
    for (uint32_t i = 0; i < memory_.memoryHeapCount; ++i) {
      const VkMemoryHeap& heap = memory_.memoryHeaps[i];
      if ((heap.flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) != 0 && heap.size > largest) {
        largest = heap.size;
        device_heap_ = i;
      }
    }
    set_name(VK_OBJECT_TYPE_DEVICE, reinterpret_cast<uint64_t>(device_), "phyxel device");
    set_name(VK_OBJECT_TYPE_QUEUE, reinterpret_cast<uint64_t>(queue_), "phyxel compute queue");
    if (transfer_queue_ != VK_NULL_HANDLE)
      set_name(VK_OBJECT_TYPE_QUEUE, reinterpret_cast<uint64_t>(transfer_queue_),
               "phyxel transfer queue");
    if (frame_queue_ != VK_NULL_HANDLE)
      set_name(VK_OBJECT_TYPE_QUEUE, reinterpret_cast<uint64_t>(frame_queue_),
               "phyxel frame queue");
    set_test_fail_allocation_after(
        test_hook("PHYXEL_TEST_FAIL_ALLOC_AFTER", "allocations").value_or(-1));
    if (const auto n = test_hook("PHYXEL_TEST_DEVICE_LOST_AT_SUBSTEP", "substeps"))
      test_lost_at_substep_ = *n;
    if (const auto n = test_hook("PHYXEL_TEST_FENCE_TIMEOUT_MS", "milliseconds"))
      options_.fence_timeout_ms = static_cast<uint32_t>(std::min<int64_t>(*n, UINT32_MAX));
  } catch (...) {
    destroy();
    throw;
  }
}

Context::~Context() {
  destroy();
}

void Context::destroy() {
  if (device_ == VK_NULL_HANDLE) return;
  if (abandoned()) {  // work may still run on the device: keep it and its instance
    (void)instance_.release();
    device_ = VK_NULL_HANDLE;
    return;
  }
  if (fn_.vkDeviceWaitIdle != nullptr) fn_.vkDeviceWaitIdle(device_);
  auto destroy_device = reinterpret_cast<PFN_vkDestroyDevice>(
      instance_->fn().vkGetDeviceProcAddr(device_, "vkDestroyDevice"));
  if (destroy_device != nullptr) destroy_device(device_, nullptr);
  device_ = VK_NULL_HANDLE;
}

uint64_t Context::available_device_memory() const {
  const uint64_t heap_size = memory_.memoryHeaps[device_heap_].size;
  if (memory_budget_) {
    auto budget = vk_struct<VkPhysicalDeviceMemoryBudgetPropertiesEXT>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT);
    auto props = vk_struct<VkPhysicalDeviceMemoryProperties2>(
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2, &budget);
    instance_->fn().vkGetPhysicalDeviceMemoryProperties2(physical_, &props);
    const uint64_t limit = budget.heapBudget[device_heap_];
    const uint64_t used = budget.heapUsage[device_heap_];
    return limit > used ? limit - used : 0;
  }
  const uint64_t used = allocated_.load();
  return heap_size > used ? heap_size - used : 0;
}

void Context::check_fits(uint64_t bytes) const {
  const uint64_t available = available_device_memory();
  if (bytes <= available) return;
  throw VulkanError("not enough GPU memory: needs " + format_bytes(bytes) + " (" +
                        std::to_string(bytes) + " bytes) but " + info_.name + " has " +
                        format_bytes(available) + " (" + std::to_string(available) +
                        " bytes) available (device-local heap " +
                        format_bytes(memory_.memoryHeaps[device_heap_].size) + ", " +
                        format_bytes(allocated_.load()) +
                        " already allocated by Phyxel); use a smaller scene, or --device cpu",
                    VK_ERROR_OUT_OF_DEVICE_MEMORY);
}

void Context::set_name(VkObjectType type, uint64_t handle, const std::string& name) const {
  if (fn_.vkSetDebugUtilsObjectNameEXT == nullptr || !instance_->debug_utils()) return;
  auto info =
      vk_struct<VkDebugUtilsObjectNameInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT);
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name.c_str();
  VK_CHECK(fn_.vkSetDebugUtilsObjectNameEXT(device_, &info));
}

}  // namespace phyxel::gpu
