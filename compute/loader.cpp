#include "compute/loader.h"

#include <dlfcn.h>

#include "compute/env.h"

namespace phyxel::gpu {
namespace {

constexpr const char* kDefaultLoader = "libvulkan.so.1";

[[noreturn]] void missing_function(const char* name) {
  throw VulkanError(
      std::string("the Vulkan driver does not provide ") + name + " (driver or loader too old?)",
      VK_ERROR_INCOMPATIBLE_DRIVER);
}

}  // namespace

std::string vulkan_loader_path(const std::string& path) {
  if (!path.empty()) return path;
  const std::string env = env_text("PHYXEL_VULKAN_LOADER");
  return env.empty() ? kDefaultLoader : env;
}

VulkanLibrary::VulkanLibrary(const std::string& path) : path_(vulkan_loader_path(path)) {
  handle_.reset(dlopen(path_.c_str(), RTLD_NOW | RTLD_LOCAL));
  if (handle_ == nullptr) {
    const char* why = dlerror();
    throw VulkanError("no Vulkan loader (" + path_ +
                          ") found: install libvulkan1 and a driver such as "
                          "mesa-vulkan-drivers, or use --device cpu" +
                          (why != nullptr ? std::string(" [") + why + "]" : std::string()),
                      VK_ERROR_INITIALIZATION_FAILED);
  }
  void* gipa = dlsym(handle_.get(), "vkGetInstanceProcAddr");
  if (gipa == nullptr) {
    throw VulkanError(path_ + " is not a Vulkan loader (no vkGetInstanceProcAddr)",
                      VK_ERROR_INITIALIZATION_FAILED);
  }
  fn_.vkGetInstanceProcAddr = reinterpret_cast<PFN_vkGetInstanceProcAddr>(gipa);
  fn_.vkEnumerateInstanceVersion = reinterpret_cast<PFN_vkEnumerateInstanceVersion>(
      fn_.vkGetInstanceProcAddr(VK_NULL_HANDLE, "vkEnumerateInstanceVersion"));
#define PHYXEL_VK_LOAD(name)                                                                 \
  fn_.name = reinterpret_cast<PFN_##name>(fn_.vkGetInstanceProcAddr(VK_NULL_HANDLE, #name)); \
  if (fn_.name == nullptr) missing_function(#name);
  PHYXEL_VK_GLOBAL_FUNCTIONS(PHYXEL_VK_LOAD)
#undef PHYXEL_VK_LOAD
  if (fn_.vkEnumerateInstanceVersion != nullptr) {
    VK_CHECK(fn_.vkEnumerateInstanceVersion(&instance_version_));
  }
  if (instance_version_ < VK_API_VERSION_1_2) {
    throw VulkanError("the Vulkan loader " + path_ + " supports Vulkan " +
                          std::to_string(VK_API_VERSION_MAJOR(instance_version_)) + "." +
                          std::to_string(VK_API_VERSION_MINOR(instance_version_)) +
                          "; Phyxel needs 1.2 or newer (or use --device cpu)",
                      VK_ERROR_INCOMPATIBLE_DRIVER);
  }
}

void VulkanLibrary::Close::operator()(void* handle) const {
  dlclose(handle);
}

InstanceFunctions load_instance_functions(const GlobalFunctions& global, VkInstance instance) {
  InstanceFunctions fn;
#define PHYXEL_VK_LOAD(name) \
  fn.name = reinterpret_cast<PFN_##name>(global.vkGetInstanceProcAddr(instance, #name));
#define PHYXEL_VK_LOAD_REQUIRED(name) \
  PHYXEL_VK_LOAD(name)                \
  if (fn.name == nullptr) missing_function(#name);
  PHYXEL_VK_INSTANCE_FUNCTIONS(PHYXEL_VK_LOAD_REQUIRED)
  PHYXEL_VK_INSTANCE_FUNCTIONS_OPTIONAL(PHYXEL_VK_LOAD)
#undef PHYXEL_VK_LOAD_REQUIRED
#undef PHYXEL_VK_LOAD
  return fn;
}

DeviceFunctions load_device_functions(const InstanceFunctions& inst, VkDevice device) {
  DeviceFunctions fn;
#define PHYXEL_VK_LOAD(name) \
  fn.name = reinterpret_cast<PFN_##name>(inst.vkGetDeviceProcAddr(device, #name));
#define PHYXEL_VK_LOAD_REQUIRED(name) \
  PHYXEL_VK_LOAD(name)                \
  if (fn.name == nullptr) missing_function(#name);
  PHYXEL_VK_DEVICE_FUNCTIONS(PHYXEL_VK_LOAD_REQUIRED)
  PHYXEL_VK_DEVICE_FUNCTIONS_OPTIONAL(PHYXEL_VK_LOAD)
#undef PHYXEL_VK_LOAD_REQUIRED
#undef PHYXEL_VK_LOAD
  return fn;
}

}  // namespace phyxel::gpu
