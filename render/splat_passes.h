// The Vulkan objects of the three splat subpasses that do not depend on the frame size: the
// render pass, descriptor-set and pipeline layouts, and the three graphics pipelines.
//
// Attachments: 0 depth (visibility, then read-only depth test), 1 and 2 the RGBA16F
// accumulation targets (colour x w, w; normal x w), 3 the RGBA8 frame. The frame attachment is
// expected in COLOR_ATTACHMENT_OPTIMAL and left there, so the two eyes of a stereo frame are
// two instances of the render pass over the two halves of one image.
#pragma once

#include "render/vk_graphics.h"

namespace phyxel::render {

inline constexpr VkFormat kAccumulationFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kFrameFormat = VK_FORMAT_R8G8B8A8_UNORM;

class SplatPasses {
 public:
  SplatPasses(const Graphics& gfx, VkFormat depth_format);
  ~SplatPasses();
  SplatPasses(const SplatPasses&) = delete;
  SplatPasses& operator=(const SplatPasses&) = delete;

  VkRenderPass render_pass() const { return render_pass_; }
  VkDescriptorSetLayout splat_set_layout() const { return splat_set_layout_; }
  VkDescriptorSetLayout shade_set_layout() const { return shade_set_layout_; }
  VkPipelineLayout splat_layout() const { return splat_layout_; }
  VkPipelineLayout shade_layout() const { return shade_layout_; }
  VkPipeline depth() const { return depth_; }
  VkPipeline accumulate() const { return accumulate_; }
  VkPipeline shade() const { return shade_; }

 private:
  void destroy();

  const Graphics* gfx_;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout splat_set_layout_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout shade_set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout splat_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout shade_layout_ = VK_NULL_HANDLE;
  VkPipeline depth_ = VK_NULL_HANDLE;
  VkPipeline accumulate_ = VK_NULL_HANDLE;
  VkPipeline shade_ = VK_NULL_HANDLE;
};

}  // namespace phyxel::render
