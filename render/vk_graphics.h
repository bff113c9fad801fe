// The graphics side of the Vulkan core for the renderer: the device entry points that
// compute/ does not load (images, render passes, graphics pipelines, draws), loaded from the
// same gpu::Context with vkGetDeviceProcAddr, and a device-local image with its view.
#pragma once

#include <cstdint>
#include <string>

#include "compute/context.h"
#include "compute/loader.h"
#include "compute/pipeline.h"

#define PHYXEL_VK_GRAPHICS_FUNCTIONS(X) \
  X(vkCreateImage)                      \
  X(vkDestroyImage)                     \
  X(vkGetImageMemoryRequirements)       \
  X(vkBindImageMemory)                  \
  X(vkCreateImageView)                  \
  X(vkDestroyImageView)                 \
  X(vkCreateSampler)                    \
  X(vkDestroySampler)                   \
  X(vkCreateRenderPass)                 \
  X(vkDestroyRenderPass)                \
  X(vkCreateFramebuffer)                \
  X(vkDestroyFramebuffer)               \
  X(vkCreateGraphicsPipelines)          \
  X(vkCmdBeginRenderPass)               \
  X(vkCmdNextSubpass)                   \
  X(vkCmdEndRenderPass)                 \
  X(vkCmdDraw)                          \
  X(vkCmdSetViewport)                   \
  X(vkCmdSetScissor)                    \
  X(vkCmdCopyImageToBuffer)             \
  X(vkCmdCopyBufferToImage)             \
  X(vkCmdBlitImage)

namespace phyxel::render {

#define PHYXEL_VK_DECLARE(name) PFN_##name name = nullptr;
struct GraphicsFunctions {
  PHYXEL_VK_GRAPHICS_FUNCTIONS(PHYXEL_VK_DECLARE)
  // Instance level, for the physical device of the context.
  PFN_vkGetPhysicalDeviceFormatProperties vkGetPhysicalDeviceFormatProperties = nullptr;
};
#undef PHYXEL_VK_DECLARE

// The graphics entry points of `ctx`'s device. Throws VulkanError when one is missing or the
// context's queue cannot do graphics (the renderer shares the solver's queue).
class Graphics {
 public:
  explicit Graphics(gpu::Context& ctx);
  gpu::Context& context() const { return *ctx_; }
  const GraphicsFunctions& fn() const { return fn_; }
  // Whether `format` with optimal tiling has all of `features`.
  bool supports(VkFormat format, VkFormatFeatureFlags features) const;

 private:
  gpu::Context* ctx_;
  gpu::VulkanLibrary library_;  // for vkGetInstanceProcAddr (the loader stays open)
  GraphicsFunctions fn_;
};

// A 2D device-local image (one allocation), with a view of all its mip levels.
class GpuImage {
 public:
  GpuImage() = default;
  GpuImage(const Graphics& gfx, uint32_t width, uint32_t height, VkFormat format,
           VkImageUsageFlags usage, VkImageAspectFlags aspect, const std::string& name,
           uint32_t mip_levels = 1);
  ~GpuImage();
  GpuImage(GpuImage&& other) noexcept;
  GpuImage& operator=(GpuImage&& other) noexcept;
  GpuImage(const GpuImage&) = delete;
  GpuImage& operator=(const GpuImage&) = delete;

  void reset();
  VkImage image() const { return image_; }
  VkImageView view() const { return view_; }
  VkFormat format() const { return format_; }
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  uint32_t mip_levels() const { return mips_; }

 private:
  const Graphics* gfx_ = nullptr;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceSize bytes_ = 0;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  uint32_t width_ = 0, height_ = 0, mips_ = 1;
};

// Records an image layout transition of all mip levels (and the memory dependency).
void image_barrier(VkCommandBuffer cmd, const gpu::DeviceFunctions& fn, VkImage image,
                   VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                   VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                   VkPipelineStageFlags dst_stages, VkAccessFlags dst_access, uint32_t base_mip = 0,
                   uint32_t mip_count = VK_REMAINING_MIP_LEVELS);

// A shader module from embedded SPIR-V (destroyed by the caller).
VkShaderModule create_shader_module(const gpu::Context& ctx, const gpu::ShaderCode& code);

}  // namespace phyxel::render
