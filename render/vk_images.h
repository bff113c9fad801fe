// Images for the renderer: the device entry points that compute/ does not load (images,
// views, samplers, buffer-to-image copies), loaded from the same gpu::Context with
// vkGetDeviceProcAddr, and a device-local image with its view. The renderer is all compute
// passes, so none of this needs a graphics queue.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/buffer.h"
#include "compute/context.h"
#include "compute/loader.h"
#include "compute/pipeline.h"
#include "render/image.h"

#define PHYXEL_VK_IMAGE_FUNCTIONS(X) \
  X(vkCreateImage)                   \
  X(vkDestroyImage)                  \
  X(vkGetImageMemoryRequirements)    \
  X(vkBindImageMemory)               \
  X(vkCreateImageView)               \
  X(vkDestroyImageView)              \
  X(vkCreateSampler)                 \
  X(vkDestroySampler)                \
  X(vkCmdCopyBufferToImage)

namespace phyxel::render {

#define PHYXEL_VK_DECLARE(name) PFN_##name name = nullptr;
struct ImageFunctions {
  PHYXEL_VK_IMAGE_FUNCTIONS(PHYXEL_VK_DECLARE)
  // Instance level, for the physical device of the context.
  PFN_vkGetPhysicalDeviceFormatProperties vkGetPhysicalDeviceFormatProperties = nullptr;
};
#undef PHYXEL_VK_DECLARE

// The image entry points of `ctx`'s device. Throws VulkanError when one is missing.
class Images {
 public:
  explicit Images(gpu::Context& ctx);
  gpu::Context& context() const { return *ctx_; }
  const ImageFunctions& fn() const { return fn_; }
  // Whether `format` with optimal tiling has all of `features`.
  bool supports(VkFormat format, VkFormatFeatureFlags features) const;

 private:
  gpu::Context* ctx_;
  gpu::VulkanLibrary library_;  // for vkGetInstanceProcAddr (the loader stays open)
  ImageFunctions fn_;
};

// A 2D device-local image (one allocation), with a view of all its mip levels.
class GpuImage {
 public:
  GpuImage() = default;
  GpuImage(const Images& images, uint32_t width, uint32_t height, VkFormat format,
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
  void destroy();  // the Vulkan objects (reset() forgets them)

  const Images* images_ = nullptr;
  VkImage image_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceSize bytes_ = 0;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  uint32_t width_ = 0, height_ = 0, mips_ = 1;
};

// The mip chain of a texture: `image` halved until it fits `max_side`, then 2 x 2 box-filtered
// halves down to 1 x 1. Throws std::invalid_argument when `image` is empty.
std::vector<RgbaImage> mip_chain(const RgbaImage& image, uint32_t max_side);

// A sampled RGBA8 texture with its full mip chain (2 x 2 box filter, built on the host, so no
// blit and no graphics queue is needed), trilinear filtering, clamped at the edges. Images
// larger than `max_side` are halved until they fit. Throws std::invalid_argument when `image`
// is empty.
class Texture {
 public:
  Texture() = default;
  Texture(const Images& images, const RgbaImage& image, uint32_t max_side);
  // From a ready mip chain (mip_chain), e.g. a video frame's.
  Texture(const Images& images, const std::vector<RgbaImage>& levels);
  ~Texture();
  Texture(Texture&& other) noexcept;
  Texture& operator=(Texture&& other) noexcept;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;

  VkImageView view() const { return image_.view(); }
  VkSampler sampler() const { return sampler_; }
  uint32_t width() const { return image_.width(); }
  uint32_t height() const { return image_.height(); }

  // New contents of the same sizes (a video frame's mip chain): copies `levels` into the
  // texture's staging buffer, for record_upload() to record the copy into a frame's command
  // buffer. The frame that last read the texture must have finished. Returns false (and stages
  // nothing) when the sizes differ.
  bool stage(const std::vector<RgbaImage>& levels);
  // Records the copy of what stage() staged (nothing when nothing was staged since).
  void record_upload(VkCommandBuffer cmd);

 private:
  void reset();
  const Images* images_ = nullptr;
  GpuImage image_;
  VkSampler sampler_ = VK_NULL_HANDLE;
  gpu::Buffer staging_;  // the mip chain, level after level
  std::vector<VkBufferImageCopy> regions_;
  bool staged_ = false;
};

// Records an image layout transition of all mip levels (and the memory dependency).
void image_barrier(VkCommandBuffer cmd, const gpu::DeviceFunctions& fn, VkImage image,
                   VkImageAspectFlags aspect, VkImageLayout from, VkImageLayout to,
                   VkPipelineStageFlags src_stages, VkAccessFlags src_access,
                   VkPipelineStageFlags dst_stages, VkAccessFlags dst_access, uint32_t base_mip = 0,
                   uint32_t mip_count = VK_REMAINING_MIP_LEVELS);

}  // namespace phyxel::render
