// Internal to render/: the state behind SplatRenderer (its pimpl) and the push-constant
// helpers that its frame recording (splat_renderer.cpp) and its backdrop layer and targets
// (splat_renderer_impl.cpp) share. Not part of the renderer's interface.
#pragma once

#include <array>
#include <memory>
#include <unordered_map>
#include <vector>

#include "render/splat_renderer.h"
#include "render/vk_images.h"

namespace phyxel::render {
namespace detail {

layout::mat4 to_mat4(const Eigen::Matrix4d& m);
layout::vec4 frustum_of(const EyeView& eye);
// Slices of a raster pass over `count` splats (splat_raster.glsl), and its invocations:
// `slices` copies of the splats rounded up to whole workgroups.
uint32_t raster_slices(uint32_t count);
uint32_t raster_invocations(uint32_t count);
layout::RasterPush raster_push(const EyeView& eye, float epsilon, uint32_t width, uint32_t height,
                               uint32_t count);
layout::ToolPush tool_push(const EyeView& eye, uint32_t width, uint32_t height, uint32_t count);
layout::RenderTool render_tool(const ToolDrawable& t);
uint32_t shade_layout(FrameLayout layout);
// Pixels from one eye's range to the next (a multiple of 64), and the accumulation buffer's
// bytes for all eyes.
uint64_t eye_stride_of(const FrameSetup& setup);
uint64_t accum_bytes_of(const FrameSetup& setup);
// Set 1 of the texturing passes: one combined image sampler (the tissue or the environment).
inline constexpr VkDescriptorSetLayoutBinding kTextureBinding{
    0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr};

}  // namespace detail

struct SplatRenderer::Impl {
  Impl(gpu::Context& c, const RendererOptions& o) : ctx(c), images(c), options(o) {}
  ~Impl();
  void create_texture_sets();
  void write_texture_set(VkDescriptorSet set, const Texture& image);
  void ensure_targets(const FrameSetup& setup);
  void grow(size_t slots);
  // Host edits of the table reach the GPU with the next frame (record_surfel_upload): the
  // blocks of kDirtyBlock slots written since, coalesced, through a mapped staging copy of
  // the table. No edit waits for the GPU.
  void mark_dirty(size_t slot);
  void mark_dirty(size_t first, size_t end);
  bool record_surfel_upload(gpu::Recorder& rec);  // whether it recorded a copy
  void index_outer_slots();                       // outer_offset / outer_slot, once
  layout::ShadePush shade_push(const FrameSetup& setup) const;
  void record_backdrop_layer(gpu::Recorder& rec, const FrameSetup& setup);
  // Parts of SplatRenderer::record (splat_renderer.cpp).
  uint32_t stage_tools();
  void record_deform(gpu::Recorder& rec, const RenderInputs& in);
  gpu::Buffer& readback_buffer(uint32_t slot);

  gpu::Context& ctx;
  Images images;
  RendererOptions options;
  VkPhysicalDeviceLimits limits{};
  gpu::Pipeline deform, visibility, accumulate, shade, tool_pass;
  bool int64_atomics = false;  // accumulate is splat_accumulate64.comp
  // deform for a solver whose pairs are in two parts (pair_buffers.glsl's specialization
  // constants: split, and the pairs of the first part), made on first use and again when the
  // first part's size changes.
  gpu::Pipeline deform_split;
  uint64_t deform_split_lo = 0;
  // The tools of the next frames; their GPU copy (mapped staging, device) grows as needed.
  std::vector<ToolDrawable> tools;
  gpu::Buffer tool_staging, tool_buffer;
  size_t tool_capacity = 0;
  uint32_t count = 0, table_phyxels = 0;
  // The surfel table as uploaded (radii scaled): the outer surface from the constructor, then
  // the cut faces appended by update_cut_surfels (cut_slot: the slot of each cut phyxel's
  // face). The device buffers hold `capacity` slots and grow by doubling.
  std::vector<layout::SurfelStatic> table;
  std::unordered_map<uint32_t, uint32_t> cut_slot;
  size_t capacity = 0;
  gpu::Buffer surfels, splats;
  static constexpr size_t kDirtyBlock = 64;
  std::vector<uint8_t> dirty;  // per block of kDirtyBlock slots: written since the last upload
  bool any_dirty = false;
  gpu::Buffer surfel_staging;  // mapped, `capacity` slots
  // Per phyxel its slots among the constructor's `outer_count` (CSR; hide_phyxels), made on
  // first use.
  size_t outer_count = 0;
  std::vector<uint32_t> outer_offset, outer_slot;
  // The backdrop's static splats (set_backdrop) and its layer: per pixel of each eye (the
  // depth buffer's indexing) its visible depth and its shaded colour, drawn by the splat and
  // shading passes once per view (`layer_view`; `layer_stale` after set_backdrop or
  // set_environment) and copied into each frame's depth buffer and under its pixels.
  gpu::Buffer backdrop, layer_depth, layer_colour;
  uint32_t backdrop_count = 0;
  bool layer_stale = true;
  FrameSetup layer_view{};
  gpu::Buffer no_weights;  // bound as the pair weights when the inputs have none
  Texture texture;
  VkDescriptorSetLayout texture_layout = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet texture_set = VK_NULL_HANDLE;
  // The environment (set_environment): its image in set 1 of the shading pass (the tissue
  // texture until there is one, never read then), the cube's frame and area ratio.
  Texture environment;
  VkDescriptorSet environment_set = VK_NULL_HANDLE;
  bool has_environment = false;
  Eigen::Matrix3d world_to_environment = Eigen::Matrix3d::Identity();
  double environment_area_ratio = 1;
  // Size-dependent targets: per pixel of each eye (eye e from e x eye_stride) the visible
  // depth and the accumulated attributes; the frame in its layout; its host copy.
  uint32_t eye_width = 0, eye_height = 0, eyes = 0, eye_stride = 0;
  gpu::Buffer depth, accum, frame;
  // The accumulation buffer needs a fill: new, or not yet zeroed by a shading pass (which
  // zeroes what it read, splat_shade.comp; the backdrop layer's shading pass too).
  bool accum_dirty = true;
  bool reads_back = true;                                           // set_readback
  std::array<gpu::Buffer, SplatRenderer::kReadbackSlots> readback;  // made on first use
  uint32_t out_width = 0, out_height = 0;
  std::unique_ptr<gpu::Recorder> recorder;
};

}  // namespace phyxel::render
