#include "render/vk_images.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include "compute/buffer.h"

namespace phyxel::render {
namespace {

// Half of `image` in each direction (at least 1 pixel), 2 x 2 box filter.
RgbaImage half_size(const RgbaImage& image) {
  RgbaImage half(std::max(1u, image.width / 2), std::max(1u, image.height / 2));
  for (uint32_t y = 0; y < half.height; ++y)
    for (uint32_t x = 0; x < half.width; ++x)
      for (int c = 0; c < 4; ++c) {
        const uint32_t x0 = std::min(2 * x, image.width - 1),
                       x1 = std::min(2 * x + 1, image.width - 1);
        const uint32_t y0 = std::min(2 * y, image.height - 1),
                       y1 = std::min(2 * y + 1, image.height - 1);
        const int sum =
            image.at(x0, y0)[c] + image.at(x1, y0)[c] + image.at(x0, y1)[c] + image.at(x1, y1)[c];
        half.at(x, y)[c] = static_cast<uint8_t>((sum + 2) / 4);
      }
  return half;
}

}  // namespace

std::vector<RgbaImage> mip_chain(const RgbaImage& source, uint32_t max_side) {
  if (source.width == 0 || source.height == 0) {
    throw std::invalid_argument("the texture is empty (0 x 0 pixels)");
  }
  std::vector<RgbaImage> levels{source};
  while (levels.back().width > max_side || levels.back().height > max_side) {
    levels.back() = half_size(levels.back());
  }
  while (levels.back().width > 1 || levels.back().height > 1) {
    levels.push_back(half_size(levels.back()));
  }
  return levels;
}

Images::Images(gpu::Context& ctx) : ctx_(&ctx), library_(ctx.instance().loader_path()) {
  const gpu::InstanceFunctions& ifn = ctx.instance().fn();
  const VkDevice device = ctx.device();
  auto missing = [&](const char* name) {
    throw VulkanError(std::string("the Vulkan driver of ") + ctx.info().name + " lacks " + name,
                      VK_ERROR_INITIALIZATION_FAILED);
  };
#define PHYXEL_VK_LOAD(name)                                                       \
  fn_.name = reinterpret_cast<PFN_##name>(ifn.vkGetDeviceProcAddr(device, #name)); \
  if (fn_.name == nullptr) missing(#name);
  PHYXEL_VK_IMAGE_FUNCTIONS(PHYXEL_VK_LOAD)
#undef PHYXEL_VK_LOAD
  fn_.vkGetPhysicalDeviceFormatProperties =
      reinterpret_cast<PFN_vkGetPhysicalDeviceFormatProperties>(library_.fn().vkGetInstanceProcAddr(
          ctx.instance().handle(), "vkGetPhysicalDeviceFormatProperties"));
  if (fn_.vkGetPhysicalDeviceFormatProperties == nullptr) {
    missing("vkGetPhysicalDeviceFormatProperties");
  }
}

bool Images::supports(VkFormat format, VkFormatFeatureFlags features) const {
  VkFormatProperties props{};
  fn_.vkGetPhysicalDeviceFormatProperties(ctx_->physical_device(), format, &props);
  return (props.optimalTilingFeatures & features) == features;
}

GpuImage::GpuImage(const Images& images, uint32_t width, uint32_t height, VkFormat format,
                   VkImageUsageFlags usage, VkImageAspectFlags aspect, const std::string& name,
                   uint32_t mip_levels)
    : images_(&images), format_(format), width_(width), height_(height), mips_(mip_levels) {
  gpu::Context& ctx = images.context();
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
  VK_CHECK(images.fn().vkCreateImage(ctx.device(), &info, nullptr, &image_));
  try {
    VkMemoryRequirements needs{};
    images.fn().vkGetImageMemoryRequirements(ctx.device(), image_, &needs);
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
    VK_CHECK(images.fn().vkBindImageMemory(ctx.device(), image_, memory_, 0));
    auto view = vk_struct<VkImageViewCreateInfo>(VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO);
    view.image = image_;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect, 0, mip_levels, 0, 1};
    VK_CHECK(images.fn().vkCreateImageView(ctx.device(), &view, nullptr, &view_));
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
    images_ = std::exchange(other.images_, nullptr);
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
  if (images_ == nullptr) return;
  gpu::Context& ctx = images_->context();
  if (!ctx.abandoned()) destroy();  // else unfinished work may still use it: leak it
  view_ = VK_NULL_HANDLE;
  image_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  bytes_ = 0;
  images_ = nullptr;
}

void GpuImage::destroy() {
  gpu::Context& ctx = images_->context();
  if (view_ != VK_NULL_HANDLE) images_->fn().vkDestroyImageView(ctx.device(), view_, nullptr);
  if (image_ != VK_NULL_HANDLE) images_->fn().vkDestroyImage(ctx.device(), image_, nullptr);
  if (memory_ != VK_NULL_HANDLE) {
    ctx.fn().vkFreeMemory(ctx.device(), memory_, nullptr);
    ctx.track_allocation(-static_cast<int64_t>(bytes_));
  }
}

Texture::Texture(const Images& images, const RgbaImage& source, uint32_t max_side)
    : Texture(images, mip_chain(source, max_side)) {}

Texture::Texture(const Images& images, const std::vector<RgbaImage>& levels) : images_(&images) {
  if (levels.empty() || levels[0].width == 0 || levels[0].height == 0) {
    throw std::invalid_argument("the texture is empty (0 x 0 pixels)");
  }
  gpu::Context& ctx = images.context();
  const uint32_t count = static_cast<uint32_t>(levels.size());
  constexpr VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  image_ = GpuImage(images, levels[0].width, levels[0].height, format,
                    VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                    VK_IMAGE_ASPECT_COLOR_BIT, "render texture", count);
  regions_.resize(count);
  size_t offset = 0;
  for (uint32_t i = 0; i < count; ++i) {
    regions_[i].bufferOffset = offset;
    regions_[i].imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, i, 0, 1};
    regions_[i].imageExtent = {levels[i].width, levels[i].height, 1};
    offset += levels[i].pixels.size();
  }
  stage(levels);
  gpu::Recorder rec(ctx, "texture upload");
  record_upload(rec.cmd());
  rec.submit_and_wait();
  staging_.reset();  // a texture that changes (stage()) makes it again and keeps it

  const bool linear = images.supports(format, VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT);
  auto info = vk_struct<VkSamplerCreateInfo>(VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO);
  info.magFilter = info.minFilter = linear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
  info.mipmapMode = linear ? VK_SAMPLER_MIPMAP_MODE_LINEAR : VK_SAMPLER_MIPMAP_MODE_NEAREST;
  info.addressModeU = info.addressModeV = info.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  info.maxLod = static_cast<float>(count);
  VK_CHECK(images.fn().vkCreateSampler(ctx.device(), &info, nullptr, &sampler_));
}

bool Texture::stage(const std::vector<RgbaImage>& levels) {
  if (levels.size() != regions_.size()) return false;
  for (size_t i = 0; i < levels.size(); ++i) {
    if (levels[i].width != regions_[i].imageExtent.width ||
        levels[i].height != regions_[i].imageExtent.height)
      return false;
  }
  if (!staging_) {
    const VkBufferImageCopy& last = regions_.back();
    const VkDeviceSize bytes =
        last.bufferOffset + VkDeviceSize{last.imageExtent.width} * last.imageExtent.height * 4;
    staging_ = gpu::Buffer(images_->context(), bytes, gpu::MemoryIntent::Upload, "texture staging");
  }
  for (size_t i = 0; i < levels.size(); ++i) {
    std::memcpy(static_cast<uint8_t*>(staging_.mapped()) + regions_[i].bufferOffset,
                levels[i].pixels.data(), levels[i].pixels.size());
  }
  staged_ = true;
  return true;
}

void Texture::record_upload(VkCommandBuffer cmd) {
  if (!staged_) return;
  const gpu::DeviceFunctions& fn = images_->context().fn();
  constexpr VkImageAspectFlags colour = VK_IMAGE_ASPECT_COLOR_BIT;
  // From UNDEFINED: every level is overwritten, the old contents need not be kept.
  image_barrier(cmd, fn, image_.image(), colour, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0,
                VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
  images_->fn().vkCmdCopyBufferToImage(cmd, staging_.handle(), image_.image(),
                                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                                       static_cast<uint32_t>(regions_.size()), regions_.data());
  image_barrier(cmd, fn, image_.image(), colour, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                VK_ACCESS_SHADER_READ_BIT);
  staged_ = false;
}

Texture::~Texture() {
  reset();
}

Texture::Texture(Texture&& other) noexcept {
  *this = std::move(other);
}

Texture& Texture::operator=(Texture&& other) noexcept {
  if (this != &other) {
    reset();
    images_ = std::exchange(other.images_, nullptr);
    image_ = std::move(other.image_);
    sampler_ = std::exchange(other.sampler_, VK_NULL_HANDLE);
    staging_ = std::move(other.staging_);
    regions_ = std::move(other.regions_);
    staged_ = std::exchange(other.staged_, false);
  }
  return *this;
}

void Texture::reset() {
  if (images_ != nullptr && sampler_ != VK_NULL_HANDLE && !images_->context().abandoned()) {
    images_->fn().vkDestroySampler(images_->context().device(), sampler_, nullptr);
  }
  sampler_ = VK_NULL_HANDLE;
  staging_.reset();
  regions_.clear();
  staged_ = false;
  image_.reset();
  images_ = nullptr;
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

}  // namespace phyxel::render
