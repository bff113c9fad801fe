#include "compute/vk_check.h"

namespace phyxel {

std::string vk_result_name(VkResult result) {
  switch (result) {
#define PHYXEL_VK_RESULT(name) \
  case name:                   \
    return #name;
    PHYXEL_VK_RESULT(VK_SUCCESS)
    PHYXEL_VK_RESULT(VK_NOT_READY)
    PHYXEL_VK_RESULT(VK_TIMEOUT)
    PHYXEL_VK_RESULT(VK_EVENT_SET)
    PHYXEL_VK_RESULT(VK_EVENT_RESET)
    PHYXEL_VK_RESULT(VK_INCOMPLETE)
    PHYXEL_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    PHYXEL_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    PHYXEL_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    PHYXEL_VK_RESULT(VK_ERROR_DEVICE_LOST)
    PHYXEL_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    PHYXEL_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    PHYXEL_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    PHYXEL_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    PHYXEL_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    PHYXEL_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    PHYXEL_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    PHYXEL_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
    PHYXEL_VK_RESULT(VK_ERROR_UNKNOWN)
    PHYXEL_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    PHYXEL_VK_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    PHYXEL_VK_RESULT(VK_ERROR_FRAGMENTATION)
    PHYXEL_VK_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    PHYXEL_VK_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
    PHYXEL_VK_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    PHYXEL_VK_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    PHYXEL_VK_RESULT(VK_SUBOPTIMAL_KHR)
    PHYXEL_VK_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
    PHYXEL_VK_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
    PHYXEL_VK_RESULT(VK_ERROR_INVALID_SHADER_NV)
#undef PHYXEL_VK_RESULT
    default:
      return "VkResult(" + std::to_string(static_cast<int>(result)) + ")";
  }
}

namespace detail {

void vk_check_failed(VkResult result, const char* call, const char* file, int line) {
  std::string message = std::string(call) + " failed at " + file + ":" + std::to_string(line) +
                        " with " + vk_result_name(result);
  if (result == VK_ERROR_DEVICE_LOST) {
    message +=
        ": the GPU stopped responding (driver timeout or a fault in a kernel); try a smaller "
        "scene, or --device cpu";
  } else if (result == VK_ERROR_OUT_OF_DEVICE_MEMORY) {
    message += ": the GPU is out of memory; try a smaller scene, or --device cpu";
  } else if (result == VK_ERROR_OUT_OF_HOST_MEMORY) {
    message += ": the computer is out of memory; try a smaller scene";
  }
  throw VulkanError(message, result);
}

}  // namespace detail
}  // namespace phyxel
