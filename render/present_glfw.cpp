#include "render/present_glfw.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "compute/vk_check.h"
#include "render/splat_renderer.h"

#define PHYXEL_PRESENT_INSTANCE_FUNCTIONS(X)   \
  X(vkDestroyInstance)                         \
  X(vkEnumeratePhysicalDevices)                \
  X(vkGetPhysicalDeviceProperties)             \
  X(vkGetPhysicalDeviceQueueFamilyProperties)  \
  X(vkGetPhysicalDeviceMemoryProperties)       \
  X(vkGetPhysicalDeviceSurfaceSupportKHR)      \
  X(vkGetPhysicalDeviceSurfaceCapabilitiesKHR) \
  X(vkGetPhysicalDeviceSurfaceFormatsKHR)      \
  X(vkDestroySurfaceKHR)                       \
  X(vkCreateDevice)                            \
  X(vkGetDeviceProcAddr)

#define PHYXEL_PRESENT_DEVICE_FUNCTIONS(X) \
  X(vkDestroyDevice)                       \
  X(vkGetDeviceQueue)                      \
  X(vkDeviceWaitIdle)                      \
  X(vkCreateSwapchainKHR)                  \
  X(vkDestroySwapchainKHR)                 \
  X(vkGetSwapchainImagesKHR)               \
  X(vkAcquireNextImageKHR)                 \
  X(vkQueuePresentKHR)                     \
  X(vkQueueSubmit)                         \
  X(vkCreateCommandPool)                   \
  X(vkDestroyCommandPool)                  \
  X(vkAllocateCommandBuffers)              \
  X(vkResetCommandPool)                    \
  X(vkBeginCommandBuffer)                  \
  X(vkEndCommandBuffer)                    \
  X(vkCmdPipelineBarrier)                  \
  X(vkCmdCopyBufferToImage)                \
  X(vkCmdClearColorImage)                  \
  X(vkCreateFence)                         \
  X(vkDestroyFence)                        \
  X(vkWaitForFences)                       \
  X(vkResetFences)                         \
  X(vkCreateSemaphore)                     \
  X(vkDestroySemaphore)                    \
  X(vkCreateBuffer)                        \
  X(vkDestroyBuffer)                       \
  X(vkGetBufferMemoryRequirements)         \
  X(vkAllocateMemory)                      \
  X(vkFreeMemory)                          \
  X(vkBindBufferMemory)                    \
  X(vkMapMemory)

namespace phyxel::render {
namespace {

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error("cannot show the viewer window: " + what);
}

}  // namespace

struct Presenter::Impl {
#define PHYXEL_DECLARE(name) PFN_##name name = nullptr;
  PHYXEL_PRESENT_INSTANCE_FUNCTIONS(PHYXEL_DECLARE)
  PHYXEL_PRESENT_DEVICE_FUNCTIONS(PHYXEL_DECLARE)
#undef PHYXEL_DECLARE

  GLFWwindow* window = nullptr;
  VkInstance instance = VK_NULL_HANDLE;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  std::string name;
  uint32_t family = 0;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkSemaphore acquired = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{};
  std::vector<VkImage> images;
  std::vector<VkSemaphore> done;  // one per swapchain image
  VkBuffer staging = VK_NULL_HANDLE;
  VkDeviceMemory staging_memory = VK_NULL_HANDLE;
  VkDeviceSize staging_bytes = 0;
  void* mapped = nullptr;

  void create_instance_and_device();
  void create_swapchain();
  void destroy_swapchain();
  void ensure_staging(VkDeviceSize bytes);
  ~Impl();
};

void Presenter::Impl::create_instance_and_device() {
  auto create_instance = reinterpret_cast<PFN_vkCreateInstance>(
      glfwGetInstanceProcAddress(nullptr, "vkCreateInstance"));
  if (create_instance == nullptr || !glfwVulkanSupported()) fail("no Vulkan loader for GLFW");
  uint32_t count = 0;
  const char** extensions = glfwGetRequiredInstanceExtensions(&count);
  if (extensions == nullptr) fail("the window system offers no Vulkan surface extension");
  auto app = vk_struct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "phyxel view";
  app.apiVersion = VK_API_VERSION_1_1;
  auto info = vk_struct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  info.pApplicationInfo = &app;
  info.enabledExtensionCount = count;
  info.ppEnabledExtensionNames = extensions;
  VK_CHECK(create_instance(&info, nullptr, &instance));
#define PHYXEL_LOAD(name)                                                           \
  name = reinterpret_cast<PFN_##name>(glfwGetInstanceProcAddress(instance, #name)); \
  if (name == nullptr) fail("the Vulkan driver lacks " #name);
  PHYXEL_PRESENT_INSTANCE_FUNCTIONS(PHYXEL_LOAD)
#undef PHYXEL_LOAD
  VK_CHECK(glfwCreateWindowSurface(instance, window, nullptr, &surface));

  uint32_t devices = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &devices, nullptr));
  std::vector<VkPhysicalDevice> list(devices);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &devices, list.data()));
  int best = -1;
  for (VkPhysicalDevice p : list) {
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(p, &families, nullptr);
    VkPhysicalDeviceProperties props{};
    vkGetPhysicalDeviceProperties(p, &props);
    const int rank = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? 3
                     : props.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 2
                                                                                  : 1;
    for (uint32_t f = 0; f < families; ++f) {
      VkBool32 ok = VK_FALSE;
      VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(p, f, surface, &ok));
      if (ok && rank > best) {
        best = rank;
        physical = p;
        family = f;
        name = props.deviceName;
      }
    }
  }
  if (physical == VK_NULL_HANDLE) fail("no Vulkan device can present to this window");
  const float priority = 1.0f;
  auto queue_info = vk_struct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
  queue_info.queueFamilyIndex = family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  const char* swapchain_extension = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
  auto device_info = vk_struct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  device_info.enabledExtensionCount = 1;
  device_info.ppEnabledExtensionNames = &swapchain_extension;
  VK_CHECK(vkCreateDevice(physical, &device_info, nullptr, &device));
#define PHYXEL_LOAD(name)                                                  \
  name = reinterpret_cast<PFN_##name>(vkGetDeviceProcAddr(device, #name)); \
  if (name == nullptr) fail("the Vulkan driver lacks " #name);
  PHYXEL_PRESENT_DEVICE_FUNCTIONS(PHYXEL_LOAD)
#undef PHYXEL_LOAD
  vkGetDeviceQueue(device, family, 0, &queue);
  auto pool_info = vk_struct<VkCommandPoolCreateInfo>(VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO);
  pool_info.queueFamilyIndex = family;
  VK_CHECK(vkCreateCommandPool(device, &pool_info, nullptr, &pool));
  auto alloc =
      vk_struct<VkCommandBufferAllocateInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO);
  alloc.commandPool = pool;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(device, &alloc, &cmd));
  auto fence_info = vk_struct<VkFenceCreateInfo>(VK_STRUCTURE_TYPE_FENCE_CREATE_INFO);
  fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &fence));
  auto semaphore = vk_struct<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
  VK_CHECK(vkCreateSemaphore(device, &semaphore, nullptr, &acquired));
}

void Presenter::Impl::create_swapchain() {
  VkSurfaceCapabilitiesKHR caps{};
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface, &caps));
  if ((caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT) == 0) {
    fail("the window's swapchain images cannot be copied to");
  }
  uint32_t count = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface, &count, formats.data()));
  if (formats.empty()) fail("the window offers no surface format");
  VkSurfaceFormatKHR chosen = formats[0];
  for (const VkSurfaceFormatKHR& f : formats) {
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
      chosen = f;
      break;
    }
  }
  format = chosen.format;
  int w = 0, h = 0;
  glfwGetFramebufferSize(window, &w, &h);
  extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) {
    extent.width =
        std::clamp(uint32_t(std::max(w, 1)), caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(uint32_t(std::max(h, 1)), caps.minImageExtent.height,
                               caps.maxImageExtent.height);
  }
  auto info = vk_struct<VkSwapchainCreateInfoKHR>(VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR);
  info.surface = surface;
  info.minImageCount = caps.maxImageCount > 0 ? std::min(caps.minImageCount + 1, caps.maxImageCount)
                                              : caps.minImageCount + 1;
  info.imageFormat = chosen.format;
  info.imageColorSpace = chosen.colorSpace;
  info.imageExtent = extent;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : static_cast<VkCompositeAlphaFlagBitsKHR>(
                                  caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always supported
  info.clipped = VK_TRUE;
  VK_CHECK(vkCreateSwapchainKHR(device, &info, nullptr, &swapchain));
  VK_CHECK(vkGetSwapchainImagesKHR(device, swapchain, &count, nullptr));
  images.resize(count);
  VK_CHECK(vkGetSwapchainImagesKHR(device, swapchain, &count, images.data()));
  done.resize(count);
  auto semaphore = vk_struct<VkSemaphoreCreateInfo>(VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO);
  for (VkSemaphore& s : done) VK_CHECK(vkCreateSemaphore(device, &semaphore, nullptr, &s));
}

void Presenter::Impl::destroy_swapchain() {
  if (device == VK_NULL_HANDLE) return;
  vkDeviceWaitIdle(device);
  for (VkSemaphore s : done) vkDestroySemaphore(device, s, nullptr);
  done.clear();
  images.clear();
  if (swapchain != VK_NULL_HANDLE) vkDestroySwapchainKHR(device, swapchain, nullptr);
  swapchain = VK_NULL_HANDLE;
}

void Presenter::Impl::ensure_staging(VkDeviceSize bytes) {
  if (bytes <= staging_bytes) return;
  vkDeviceWaitIdle(device);
  if (staging != VK_NULL_HANDLE) vkDestroyBuffer(device, staging, nullptr);
  if (staging_memory != VK_NULL_HANDLE) vkFreeMemory(device, staging_memory, nullptr);
  auto info = vk_struct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = bytes;
  info.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  VK_CHECK(vkCreateBuffer(device, &info, nullptr, &staging));
  VkMemoryRequirements needs{};
  vkGetBufferMemoryRequirements(device, staging, &needs);
  VkPhysicalDeviceMemoryProperties memory{};
  vkGetPhysicalDeviceMemoryProperties(physical, &memory);
  constexpr VkMemoryPropertyFlags wanted =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  uint32_t type = UINT32_MAX;
  for (uint32_t t = 0; t < memory.memoryTypeCount && type == UINT32_MAX; ++t)
    if ((needs.memoryTypeBits & (1u << t)) &&
        (memory.memoryTypes[t].propertyFlags & wanted) == wanted)
      type = t;
  if (type == UINT32_MAX) fail("no host-visible memory for the frame copy");
  auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
  alloc.allocationSize = needs.size;
  alloc.memoryTypeIndex = type;
  VK_CHECK(vkAllocateMemory(device, &alloc, nullptr, &staging_memory));
  VK_CHECK(vkBindBufferMemory(device, staging, staging_memory, 0));
  VK_CHECK(vkMapMemory(device, staging_memory, 0, VK_WHOLE_SIZE, 0, &mapped));
  staging_bytes = bytes;
}

Presenter::Impl::~Impl() {
  if (device != VK_NULL_HANDLE) {
    destroy_swapchain();
    if (staging != VK_NULL_HANDLE) vkDestroyBuffer(device, staging, nullptr);
    if (staging_memory != VK_NULL_HANDLE) vkFreeMemory(device, staging_memory, nullptr);
    if (acquired != VK_NULL_HANDLE) vkDestroySemaphore(device, acquired, nullptr);
    if (fence != VK_NULL_HANDLE) vkDestroyFence(device, fence, nullptr);
    if (pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, pool, nullptr);
    vkDestroyDevice(device, nullptr);
  }
  if (surface != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance, surface, nullptr);
  if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
}

Presenter::Presenter(GLFWwindow* window) : impl_(std::make_unique<Impl>()) {
  impl_->window = window;
  impl_->create_instance_and_device();
  impl_->create_swapchain();
}

Presenter::~Presenter() = default;

std::string Presenter::device_name() const {
  return impl_->name;
}

void Presenter::present(const RgbaImage& frame) {
  Impl& m = *impl_;
  int w = 0, h = 0;
  glfwGetFramebufferSize(m.window, &w, &h);
  if (w == 0 || h == 0) return;  // minimised
  if (uint32_t(w) != m.extent.width || uint32_t(h) != m.extent.height) {
    m.destroy_swapchain();
    m.create_swapchain();
  }
  VK_CHECK(m.vkWaitForFences(m.device, 1, &m.fence, VK_TRUE, UINT64_MAX));
  uint32_t index = 0;
  VkResult acquired = m.vkAcquireNextImageKHR(m.device, m.swapchain, UINT64_MAX, m.acquired,
                                              VK_NULL_HANDLE, &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
    m.destroy_swapchain();
    m.create_swapchain();
    return;
  }
  if (acquired != VK_SUBOPTIMAL_KHR) VK_CHECK(acquired);
  VK_CHECK(m.vkResetFences(m.device, 1, &m.fence));

  // The frame into the staging buffer, rows of the swapchain's width, R and B swapped for
  // BGRA formats.
  const uint32_t cw = std::min(frame.width, m.extent.width);
  const uint32_t ch = std::min(frame.height, m.extent.height);
  m.ensure_staging(VkDeviceSize(std::max(cw, 1u)) * std::max(ch, 1u) * 4);
  const bool bgra = m.format == VK_FORMAT_B8G8R8A8_UNORM || m.format == VK_FORMAT_B8G8R8A8_SRGB;
  auto* out = static_cast<uint8_t*>(m.mapped);
  for (uint32_t y = 0; y < ch; ++y) {
    const uint8_t* row = frame.at(0, y);
    uint8_t* dst = out + size_t(y) * cw * 4;
    if (!bgra) {
      std::memcpy(dst, row, size_t(cw) * 4);
      continue;
    }
    for (uint32_t x = 0; x < cw; ++x) {
      dst[4 * x + 0] = row[4 * x + 2];
      dst[4 * x + 1] = row[4 * x + 1];
      dst[4 * x + 2] = row[4 * x + 0];
      dst[4 * x + 3] = 255;
    }
  }

  VK_CHECK(m.vkResetCommandPool(m.device, m.pool, 0));
  auto begin = vk_struct<VkCommandBufferBeginInfo>(VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO);
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(m.vkBeginCommandBuffer(m.cmd, &begin));
  auto barrier = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = m.images[index];
  barrier.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  barrier.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  barrier.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  m.vkCmdPipelineBarrier(m.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &barrier);
  VkClearColorValue background{};
  for (int c = 0; c < 3; ++c) background.float32[c] = kBackground[c] / 255.0f;
  background.float32[3] = 1.0f;
  m.vkCmdClearColorImage(m.cmd, m.images[index], VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &background,
                         1, &barrier.subresourceRange);
  barrier.oldLayout = barrier.newLayout;
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  m.vkCmdPipelineBarrier(m.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &barrier);
  if (cw > 0 && ch > 0) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {cw, ch, 1};
    m.vkCmdCopyBufferToImage(m.cmd, m.staging, m.images[index],
                             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  }
  barrier.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  barrier.dstAccessMask = 0;
  m.vkCmdPipelineBarrier(m.cmd, VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0, nullptr, 1,
                         &barrier);
  VK_CHECK(m.vkEndCommandBuffer(m.cmd));

  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  auto submit = vk_struct<VkSubmitInfo>(VK_STRUCTURE_TYPE_SUBMIT_INFO);
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &m.acquired;
  submit.pWaitDstStageMask = &wait_stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &m.cmd;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &m.done[index];
  VK_CHECK(m.vkQueueSubmit(m.queue, 1, &submit, m.fence));
  auto present = vk_struct<VkPresentInfoKHR>(VK_STRUCTURE_TYPE_PRESENT_INFO_KHR);
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &m.done[index];
  present.swapchainCount = 1;
  present.pSwapchains = &m.swapchain;
  present.pImageIndices = &index;
  const VkResult shown = m.vkQueuePresentKHR(m.queue, &present);
  if (shown == VK_ERROR_OUT_OF_DATE_KHR || shown == VK_SUBOPTIMAL_KHR) {
    m.destroy_swapchain();
    m.create_swapchain();
  } else {
    VK_CHECK(shown);
  }
}

}  // namespace phyxel::render
