#include "compute/instance.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace phyxel::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  const char* message = data != nullptr && data->pMessage != nullptr ? data->pMessage : "";
  static_cast<ValidationLog*>(user)->add(severity, message);
  return VK_FALSE;
}

std::vector<VkExtensionProperties> instance_extensions(const GlobalFunctions& fn,
                                                       const char* layer) {
  uint32_t count = 0;
  VK_CHECK(fn.vkEnumerateInstanceExtensionProperties(layer, &count, nullptr));
  std::vector<VkExtensionProperties> out(count);
  VK_CHECK(fn.vkEnumerateInstanceExtensionProperties(layer, &count, out.data()));
  out.resize(count);
  return out;
}

bool contains(const std::vector<VkExtensionProperties>& list, const char* name) {
  return std::any_of(list.begin(), list.end(), [&](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, name) == 0;
  });
}

bool has_layer(const GlobalFunctions& fn, const char* name) {
  uint32_t count = 0;
  VK_CHECK(fn.vkEnumerateInstanceLayerProperties(&count, nullptr));
  std::vector<VkLayerProperties> layers(count);
  VK_CHECK(fn.vkEnumerateInstanceLayerProperties(&count, layers.data()));
  return std::any_of(layers.begin(), layers.begin() + count, [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

}  // namespace

void ValidationLog::add(VkDebugUtilsMessageSeverityFlagBitsEXT severity, const char* message) {
  const bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
  const bool warning = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) != 0;
  if (!error && !warning) return;
  // A hazard of the sever beside the stress pass against that pass (a plain dispatch; the
  // sever's own is indirect): by design (kSeverBesideStressPipeline).
  const std::string bracketed = std::string("[") + kSeverBesideStressPipeline + "]";
  if (std::strstr(message, "SYNC-HAZARD") != nullptr &&
      std::strstr(message, bracketed.c_str()) != nullptr &&
      std::strstr(message, "command: vkCmdDispatch,") != nullptr) {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++exempt_;
    return;
  }
  std::fprintf(stderr, "vulkan validation %s: %s\n", error ? "error" : "warning", message);
  const std::lock_guard<std::mutex> lock(mutex_);
  (error ? errors_ : warnings_) += 1;
  if (messages_.size() < kMaxKept) {
    messages_.push_back(std::string(error ? "error: " : "warning: ") + message);
  }
}

uint32_t ValidationLog::error_count() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return errors_;
}

uint32_t ValidationLog::exempt_count() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return exempt_;
}

uint32_t ValidationLog::warning_count() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return warnings_;
}

std::vector<std::string> ValidationLog::messages() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return messages_;
}

std::string ValidationLog::summary() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  std::string out =
      std::to_string(errors_) + " validation errors, " + std::to_string(warnings_) + " warnings";
  for (const std::string& m : messages_) out += "\n  " + m;
  return out;
}

Instance::Instance(const InstanceOptions& options) : library_(options.loader_path) {
  const GlobalFunctions& g = library_.fn();
  api_version_ =
      library_.instance_version() >= VK_API_VERSION_1_3 ? VK_API_VERSION_1_3 : VK_API_VERSION_1_2;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  const std::vector<VkExtensionProperties> available = instance_extensions(g, nullptr);
  debug_utils_ = contains(available, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  bool validation_features = false;
  if (options.validation) {
    if (!has_layer(g, kValidationLayer)) {
      throw VulkanError(
          "Vulkan validation was requested but the layer VK_LAYER_KHRONOS_validation is not "
          "installed: install the Debian package vulkan-validationlayers (or run without "
          "validation)",
          VK_ERROR_LAYER_NOT_PRESENT);
    }
    layers.push_back(kValidationLayer);
    const std::vector<VkExtensionProperties> from_layer = instance_extensions(g, kValidationLayer);
    debug_utils_ = debug_utils_ || contains(from_layer, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    validation_features = contains(from_layer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    if (!debug_utils_) {
      throw VulkanError("the Vulkan validation layer offers no VK_EXT_debug_utils",
                        VK_ERROR_EXTENSION_NOT_PRESENT);
    }
    if (validation_features) extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    log_ = std::make_shared<ValidationLog>();
  }
  if (debug_utils_) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

  auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "phyxel";
  app.applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0);
  app.pEngineName = "phyxel";
  app.engineVersion = app.applicationVersion;
  app.apiVersion = api_version_;

  // The messenger is chained into instance creation too, so that vkCreateInstance and
  // vkDestroyInstance are validated.
  auto messenger = vk_struct<VkDebugUtilsMessengerCreateInfoEXT>(
      VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_validation_message;
  messenger.pUserData = log_.get();
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  auto features = vk_struct<VkValidationFeaturesEXT>(VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT);
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  if (validation_features) messenger.pNext = &features;

  auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pNext = log_ != nullptr ? &messenger : nullptr;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  const VkResult created = g.vkCreateInstance(&info, nullptr, &instance_);
  if (created == VK_ERROR_INCOMPATIBLE_DRIVER) {
    throw VulkanError(
        "no Vulkan device found (the loader found no driver): install a driver such as "
        "mesa-vulkan-drivers, or use --device cpu",
        created);
  }
  VK_CHECK(created);
  try {
    fn_ = load_instance_functions(g, instance_);
    if (log_ != nullptr) {
      if (fn_.vkCreateDebugUtilsMessengerEXT == nullptr) {
        throw VulkanError("vkCreateDebugUtilsMessengerEXT is missing",
                          VK_ERROR_EXTENSION_NOT_PRESENT);
      }
      messenger.pNext = nullptr;
      VK_CHECK(fn_.vkCreateDebugUtilsMessengerEXT(instance_, &messenger, nullptr, &messenger_));
    }
    uint32_t count = 0;
    VK_CHECK(fn_.vkEnumeratePhysicalDevices(instance_, &count, nullptr));
    physical_.resize(count);
    VK_CHECK(fn_.vkEnumeratePhysicalDevices(instance_, &count, physical_.data()));
    physical_.resize(count);
    for (uint32_t i = 0; i < count; ++i) {
      devices_.push_back(query_device_info(fn_, physical_[i], i));
    }
  } catch (...) {
    destroy();
    throw;
  }
}

Instance::~Instance() {
  destroy();
}

void Instance::destroy() {
  if (instance_ == VK_NULL_HANDLE) return;
  if (messenger_ != VK_NULL_HANDLE) {
    fn_.vkDestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
  }
  auto destroy_instance = reinterpret_cast<PFN_vkDestroyInstance>(
      library_.fn().vkGetInstanceProcAddr(instance_, "vkDestroyInstance"));
  if (destroy_instance != nullptr) destroy_instance(instance_, nullptr);
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

}  // namespace phyxel::gpu
