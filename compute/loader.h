// The Vulkan loader library, opened at run time with dlopen so that a machine without
// libvulkan.so.1 gets a clear error instead of failing to start. Function tables are plain
// structs owned by whoever owns the instance or device: no global state.
#pragma once

#include <memory>
#include <string>

#include "compute/vk_functions.h"

namespace phyxel::gpu {

// The library to open: `path` when non-empty, else $PHYXEL_VULKAN_LOADER when set, else
// "libvulkan.so.1" (found through the usual dynamic-linker search).
std::string vulkan_loader_path(const std::string& path = {});

class VulkanLibrary {
 public:
  // Throws VulkanError (VK_ERROR_INITIALIZATION_FAILED) when the library cannot be opened or
  // is not a Vulkan loader, and (VK_ERROR_INCOMPATIBLE_DRIVER) when it is older than 1.2.
  explicit VulkanLibrary(const std::string& path = {});

  const GlobalFunctions& fn() const { return fn_; }
  uint32_t instance_version() const { return instance_version_; }
  const std::string& path() const { return path_; }

 private:
  struct Close {
    void operator()(void* handle) const;
  };
  std::unique_ptr<void, Close> handle_;
  std::string path_;
  GlobalFunctions fn_;
  uint32_t instance_version_ = VK_API_VERSION_1_0;
};

// Required entry points missing from the driver throw VulkanError; optional ones stay null.
InstanceFunctions load_instance_functions(const GlobalFunctions& global, VkInstance instance);
DeviceFunctions load_device_functions(const InstanceFunctions& inst, VkDevice device);

}  // namespace phyxel::gpu
