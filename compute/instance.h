// A Vulkan instance: the loader library, the instance function table, the optional
// validation layer with a messenger that counts what it reports, and the physical devices.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "compute/device_info.h"
#include "compute/loader.h"

namespace phyxel::gpu {

// What the validation layer reported. Thread-safe: the layer may call from any thread.
// Tests assert error_count() == 0 (and print messages() when it is not).
// The pipeline name of tool_sever beside the stress pass (GpuSolverOptions::sever_beside_stress):
// it reads and writes buffers that pass reads, with no barrier between them by design (its last
// workgroup waits for that pass, then redoes the stress it may have read stale pairs for), so
// ValidationLog does not count synchronization validation's hazards of it against a dispatch.
constexpr const char* kSeverBesideStressPipeline = "tool_sever_beside_stress";

class ValidationLog {
 public:
  void add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* message);
  uint32_t error_count() const;
  uint32_t exempt_count() const;  // the hazards of kSeverBesideStressPipeline left uncounted
  uint32_t warning_count() const;
  // Error and warning messages in arrival order (the first kMaxKept of them).
  std::vector<std::string> messages() const;
  std::string summary() const;  // "N errors, M warnings" followed by the messages

  static constexpr size_t kMaxKept = 64;

 private:
  mutable std::mutex mutex_;
  uint32_t errors_ = 0;
  uint32_t warnings_ = 0;
  uint32_t exempt_ = 0;
  std::vector<std::string> messages_;
};

struct InstanceOptions {
  // VK_LAYER_KHRONOS_validation with synchronization validation; missing layer → VulkanError.
  bool validation = false;
  // Library to open; empty: $PHYXEL_VULKAN_LOADER, else libvulkan.so.1 (see loader.h).
  std::string loader_path;
};

class Instance {
 public:
  explicit Instance(const InstanceOptions& options = {});
  ~Instance();
  Instance(const Instance&) = delete;
  Instance& operator=(const Instance&) = delete;

  const InstanceFunctions& fn() const { return fn_; }
  VkInstance handle() const { return instance_; }
  uint32_t api_version() const { return api_version_; }  // 1.2 or 1.3
  const std::string& loader_path() const { return library_.path(); }
  uint32_t loader_version() const { return library_.instance_version(); }
  bool debug_utils() const { return debug_utils_; }  // VK_EXT_debug_utils enabled
  bool validation() const { return log_ != nullptr; }
  // Null without validation. Shared so that it outlives the instance (and still holds what
  // the layer said while the device and instance were destroyed).
  std::shared_ptr<const ValidationLog> validation_log() const { return log_; }

  const std::vector<DeviceInfo>& devices() const { return devices_; }
  VkPhysicalDevice physical_device(uint32_t index) const { return physical_.at(index); }

 private:
  void destroy();

  VulkanLibrary library_;
  InstanceFunctions fn_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::shared_ptr<ValidationLog> log_;
  uint32_t api_version_ = VK_API_VERSION_1_2;
  bool debug_utils_ = false;
  std::vector<VkPhysicalDevice> physical_;
  std::vector<DeviceInfo> devices_;
};

}  // namespace phyxel::gpu
