// The Vulkan entry points Phyxel uses, as X-macro lists (volk-shaped, our own code). To use
// another function, add it to the right list: global (no instance), instance (loaded with
// vkGetInstanceProcAddr) or device (loaded with vkGetDeviceProcAddr, dispatched without the
// loader trampoline). The *_OPTIONAL lists come from extensions and may stay null.
#pragma once

#include "compute/vk_check.h"

#define PHYXEL_VK_GLOBAL_FUNCTIONS(X)       \
  X(vkCreateInstance)                       \
  X(vkEnumerateInstanceExtensionProperties) \
  X(vkEnumerateInstanceLayerProperties)

#define PHYXEL_VK_INSTANCE_FUNCTIONS(X)       \
  X(vkDestroyInstance)                        \
  X(vkEnumeratePhysicalDevices)               \
  X(vkGetPhysicalDeviceProperties)            \
  X(vkGetPhysicalDeviceProperties2)           \
  X(vkGetPhysicalDeviceFeatures2)             \
  X(vkGetPhysicalDeviceMemoryProperties)      \
  X(vkGetPhysicalDeviceMemoryProperties2)     \
  X(vkGetPhysicalDeviceQueueFamilyProperties) \
  X(vkEnumerateDeviceExtensionProperties)     \
  X(vkCreateDevice)                           \
  X(vkGetDeviceProcAddr)

#define PHYXEL_VK_INSTANCE_FUNCTIONS_OPTIONAL(X) \
  X(vkCreateDebugUtilsMessengerEXT)              \
  X(vkDestroyDebugUtilsMessengerEXT)

#define PHYXEL_VK_DEVICE_FUNCTIONS(X) \
  X(vkDestroyDevice)                  \
  X(vkGetDeviceQueue)                 \
  X(vkDeviceWaitIdle)                 \
  X(vkQueueSubmit)                    \
  X(vkCreateBuffer)                   \
  X(vkDestroyBuffer)                  \
  X(vkGetBufferMemoryRequirements)    \
  X(vkAllocateMemory)                 \
  X(vkFreeMemory)                     \
  X(vkBindBufferMemory)               \
  X(vkMapMemory)                      \
  X(vkUnmapMemory)                    \
  X(vkInvalidateMappedMemoryRanges)   \
  X(vkCreateShaderModule)             \
  X(vkDestroyShaderModule)            \
  X(vkCreateDescriptorSetLayout)      \
  X(vkDestroyDescriptorSetLayout)     \
  X(vkCreatePipelineLayout)           \
  X(vkDestroyPipelineLayout)          \
  X(vkCreateComputePipelines)         \
  X(vkDestroyPipeline)                \
  X(vkCreateDescriptorPool)           \
  X(vkDestroyDescriptorPool)          \
  X(vkResetDescriptorPool)            \
  X(vkAllocateDescriptorSets)         \
  X(vkUpdateDescriptorSets)           \
  X(vkCreateCommandPool)              \
  X(vkDestroyCommandPool)             \
  X(vkResetCommandPool)               \
  X(vkAllocateCommandBuffers)         \
  X(vkBeginCommandBuffer)             \
  X(vkEndCommandBuffer)               \
  X(vkCmdBindPipeline)                \
  X(vkCmdBindDescriptorSets)          \
  X(vkCmdPushConstants)               \
  X(vkCmdDispatch)                    \
  X(vkCmdDispatchIndirect)            \
  X(vkCmdPipelineBarrier)             \
  X(vkCmdCopyBuffer)                  \
  X(vkCmdFillBuffer)                  \
  X(vkCmdResetQueryPool)              \
  X(vkCmdWriteTimestamp)              \
  X(vkCreateQueryPool)                \
  X(vkDestroyQueryPool)               \
  X(vkGetQueryPoolResults)            \
  X(vkCreateFence)                    \
  X(vkDestroyFence)                   \
  X(vkResetFences)                    \
  X(vkWaitForFences)                  \
  X(vkCreateSemaphore)                \
  X(vkDestroySemaphore)

#define PHYXEL_VK_DEVICE_FUNCTIONS_OPTIONAL(X) \
  X(vkCmdPushDescriptorSetKHR)                 \
  X(vkSetDebugUtilsObjectNameEXT)

namespace phyxel::gpu {

#define PHYXEL_VK_DECLARE(name) PFN_##name name = nullptr;

// Loaded from libvulkan.so.1 before any instance exists.
struct GlobalFunctions {
  PFN_vkGetInstanceProcAddr vkGetInstanceProcAddr = nullptr;
  PFN_vkEnumerateInstanceVersion vkEnumerateInstanceVersion = nullptr;  // null on 1.0 loaders
  PHYXEL_VK_GLOBAL_FUNCTIONS(PHYXEL_VK_DECLARE)
};

// One table per VkInstance.
struct InstanceFunctions {
  PHYXEL_VK_INSTANCE_FUNCTIONS(PHYXEL_VK_DECLARE)
  PHYXEL_VK_INSTANCE_FUNCTIONS_OPTIONAL(PHYXEL_VK_DECLARE)
};

// One table per VkDevice.
struct DeviceFunctions {
  PHYXEL_VK_DEVICE_FUNCTIONS(PHYXEL_VK_DECLARE)
  PHYXEL_VK_DEVICE_FUNCTIONS_OPTIONAL(PHYXEL_VK_DECLARE)
};

#undef PHYXEL_VK_DECLARE

}  // namespace phyxel::gpu
