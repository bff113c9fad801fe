#include "render/vk_graphics.h"

#include <utility>
#include <vector>

#include "compute/buffer.h"

namespace phyxel::render {

Graphics::Graphics(gpu::Context& ctx) : ctx_(&ctx), library_(ctx.instance().loader_path()) {
  const gpu::InstanceFunctions& ifn = ctx.instance().fn();
  uint32_t families = 0;
  ifn.vkGetPhysicalDeviceQueueFamilyProperties(ctx.physical_device(), &families, nullptr);
  std::vector<VkQueueFamilyProperties> props(families);
  ifn.vkGetPhysicalDeviceQueueFamilyProperties(ctx.physical_device(), &families, props.data());
  if (ctx.queue_family() >= families ||
      (props[ctx.queue_family()].queueFlags & VK_QUEUE_GRAPHICS_BIT) == 0) {
    throw VulkanError("the renderer needs a graphics queue, but " + ctx.info().name +
                          " offers only compute on the solver's queue family; choose another "
                          "device, or run with --render none",
                      VK_ERROR_FEATURE_NOT_PRESENT);
  }
  const VkDevice device = ctx.device();
  auto missing = [&](const char* name) {
    throw VulkanError(std::string("the Vulkan driver of ") + ctx.info().name + " lacks " + name,
                      VK_ERROR_INITIALIZATION_FAILED);
  };
#define PHYXEL_VK_LOAD(name)                                                       \
  fn_.name = reinterpret_cast<PFN_##name>(ifn.vkGetDeviceProcAddr(device, #name)); \
  if (fn_.name == nullptr) missing(#name);
  PHYXEL_VK_GRAPHICS_FUNCTIONS(PHYXEL_VK_LOAD)
#undef PHYXEL_VK_LOAD
  fn_.vkGetPhysicalDeviceFormatProperties =
      reinterpret_cast<PFN_vkGetPhysicalDeviceFormatProperties>(library_.fn().vkGetInstanceProcAddr(
          ctx.instance().handle(), "vkGetPhysicalDeviceFormatProperties"));
  if (fn_.vkGetPhysicalDeviceFormatProperties == nullptr) {
    missing("vkGetPhysicalDeviceFormatProperties");
  }
}

bool Graphics::supports(VkFormat format, VkFormatFeatureFlags features) const {
  VkFormatProperties props{};
  fn_.vkGetPhysicalDeviceFormatProperties(ctx_->physical_device(), format, &props);
  return (props.optimalTilingFeatures & features) == features;
}

GpuImage::GpuImage(const Graphics& gfx, uint32_t width, uint32_t height, VkFormat format,
                   VkImageUsageFlags usage, VkImageAspectFlags aspect, const std::string& name,
                   uint32_t mip_levels)
    : gfx_(&gfx), format_(format), width_(width), height_(height), mips_(mip_levels) {
  gpu::Context& ctx = gfx.context();
  const gpu::DeviceFunctions& fn = ctx.fn();
  auto info = vk_struct<VkImageCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO);
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = mip_levels;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VK_CHECK(gfx.fn().vkCreateImage(ctx.device(), &info, nullptr, &image_));
  try {
    VkMemoryRequirements needs{};
    gfx.fn().vkGetImageMemoryRequirements(ctx.device(), image_, &needs);
    ctx.check_fits(needs.size);
    const uint32_t type = gpu::choose_memory_type(ctx.memory_properties(), needs.memoryTypeBits,
                                                  gpu::MemoryIntent::Device);
    if (type == UINT32_MAX) {
      throw VulkanError("no device memory type for image '" + name + "' on " + ctx.info().name,
                        VK_ERROR_FEATURE_NOT_PRESENT);
    }
    auto alloc = vk_struct<VkMemoryAllocateInfo>(VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO);
    alloc.allocationSize = needs.size;
    alloc.memoryTypeIndex = type;
    VK_CHECK(fn.vkAllocateMemory(ctx.device(), &alloc, nullptr, &memory_));
    bytes_ = needs.size;
    ctx.track_allocation(static_cast<int64_t>(bytes_));
    VK_CHECK(gfx.fn().vkBindImageMemory(ctx.device(), image_, memory_, 0));
    auto view = vk_struct<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    view.image = image_;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect, 0, mip_levels, 0, 1};
    VK_CHECK(gfx.fn().vkCreateImageView(ctx.device(), &view, nullptr, &view_));
    ctx.set_name(VK_OBJECT_TYPE_IMAGE, reinterpret_cast<uint64_t>(image_), name);
  } catch (...) {
    reset();
    throw;
  }
}

GpuImage::~GpuImage() {
  reset();
}

GpuImage::GpuImage(GpuImage&& other) noexcept {
  *this = std::move(other);
}

GpuImage& GpuImage::operator=(GpuImage&& other) noexcept {
  if (this != &other) {
    reset();
    gfx_ = std::exchange(other.gfx_, nullptr);
    image_ = std::exchange(other.image_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
    bytes_ = std::exchange(other.bytes_, 0);
    format_ = other.format_;
    width_ = other.width_;
    height_ = other.height_;
    mips_ = other.mips_;
  }
  return *this;
}

void GpuImage::reset() {
  if (gfx_ == nullptr) return;
  gpu::Context& ctx = gfx_->context();
  if (view_ != VK_NULL_HANDLE) gfx_->fn().vkDestroyImageView(ctx.device(), view_, nullptr);
  if (image_ != VK_NULL_HANDLE) gfx_->fn().vkDestroyImage(ctx.device(), image_, nullptr);
  if (memory_ != VK_NULL_HANDLE) {
    ctx.fn().vkFreeMemory(ctx.device(), memory_, nullptr);
    ctx.track_allocation(-static_cast<int64_t>(bytes_));
  }
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  bytes_ = 0;
  gfx_ = nullptr;
}

void image_barrier(VkCommandBuffer cmd, const gpu::DeviceFunctions& fn, VkImage image,
                   VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                   VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                   VkPipelineStageFlags dst_stages, VkAccessFlags dst_access, uint32_t base_mip,
                   uint32_t mip_count) {
  auto b = vk_struct<VkImageMemoryBarrier>(VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER);
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, base_mip, mip_count, 0, 1};
  fn.vkCmdPipelineBarrier(cmd, src_stages, dst_stages, 0, 0, nullptr, 0, nullptr, 1, &b);
}

VkShaderModule create_shader_module(const gpu::Context& ctx, const gpu::ShaderCode& code) {
  auto info = vk_struct<VkShaderModuleCreateInfo>(VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO);
  info.codeSize = code.bytes;
  info.pCode = code.words;
  VkShaderModule module = VK_NULL_HANDLE;
  VK_CHECK(ctx.fn().vkCreateShaderModule(ctx.device(), &info, nullptr, &module));
  return module;
}

}  // namespace phyxel::render
