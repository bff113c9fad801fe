// VulkanError and VK_CHECK: every Vulkan call that can fail goes through VK_CHECK, in every
// build type. A failure throws a VulkanError naming the call, file:line and the VkResult.
#pragma once

#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace phyxel {

class VulkanError : public std::runtime_error {
 public:
  explicit VulkanError(const std::string& message, VkResult result = VK_ERROR_UNKNOWN)
      : std::runtime_error(message), result_(result) {}
  VkResult result() const { return result_; }

 private:
  VkResult result_;
};

// A Vulkan structure with every member zero but sType (and pNext): avoids listing all members
// (-Wmissing-field-initializers) without leaving any uninitialized.
template <class T>
T vk_struct(VkStructureType type, void* next = nullptr) {
  T s{};
  s.sType = type;
  s.pNext = next;
  return s;
}

// "VK_ERROR_DEVICE_LOST", ...; "VkResult(-12345)" for codes this build does not know.
std::string vk_result_name(VkResult result);

namespace detail {
[[noreturn]] void vk_check_failed(VkResult result, const char* call, const char* file, int line);
}  // namespace detail

}  // namespace phyxel

// Anything but VK_SUCCESS throws; calls whose other success codes (VK_TIMEOUT, VK_INCOMPLETE,
// VK_NOT_READY) are expected handle them explicitly instead of using VK_CHECK.
#define VK_CHECK(call)                                                                       \
  do {                                                                                       \
    const VkResult phyxel_vk_check_result_ = (call);                                         \
    if (phyxel_vk_check_result_ != VK_SUCCESS)                                               \
      ::phyxel::detail::vk_check_failed(phyxel_vk_check_result_, #call, __FILE__, __LINE__); \
  } while (0)
