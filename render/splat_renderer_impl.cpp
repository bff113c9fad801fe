// SplatRenderer's state (splat_renderer_impl.h): its descriptor sets, its size-dependent
// targets, the growth of its surfel buffers, the shading pass's push constants and the
// backdrop layer; and the push-constant helpers the frame recording shares.
#include "render/splat_renderer_impl.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace phyxel::render {
namespace detail {

layout::mat4 to_mat4(const Eigen::Matrix4d& m) {
  layout::mat4 out{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out.m[c * 4 + r] = static_cast<float>(m(r, c));
  return out;
}

layout::vec4 frustum_of(const EyeView& eye) {
  const Frustum& f = eye.frustum;
  return {float(f.left), float(f.right), float(f.bottom), float(f.top)};
}

// Slices of a raster pass over `count` splats (splat_raster.glsl): enough workgroups that a
// few thousand splats, each covering thousands of pixels (a backdrop, tissue seen close up),
// keep every shader core busy; one for a million splats.
constexpr uint32_t kRasterGroupsWanted = 4096, kMaxRasterSlices = 32;
constexpr uint32_t kGroup = PHYXEL_WORKGROUP_SIZE;
uint32_t raster_slices(uint32_t count) {
  const uint32_t groups = std::max<uint32_t>(1, (count + kGroup - 1) / kGroup);
  return std::clamp<uint32_t>(kRasterGroupsWanted / groups, 1, kMaxRasterSlices);
}
// Invocations of a raster pass: `slices` copies of the splats rounded up to whole workgroups.
uint32_t raster_invocations(uint32_t count) {
  const uint32_t padded = (count + kGroup - 1) / kGroup * kGroup;
  return padded * raster_slices(count);
}

layout::RasterPush raster_push(const EyeView& eye, float epsilon, uint32_t width, uint32_t height,
                               uint32_t count) {
  layout::RasterPush p{};
  p.view = to_mat4(eye.view);
  p.frustum = frustum_of(eye);
  p.depth = {float(eye.frustum.near), float(eye.frustum.far), epsilon, 0.0f};
  p.target = {width, height, count, raster_slices(count)};
  return p;
}

layout::ToolPush tool_push(const EyeView& eye, uint32_t width, uint32_t height, uint32_t count) {
  layout::ToolPush p{};
  p.view = to_mat4(eye.view);
  p.frustum = frustum_of(eye);
  p.depth = {float(eye.frustum.near), float(eye.frustum.far), 0.0f, 0.0f};
  p.target = {width, height, count, 0};
  return p;
}

layout::RenderTool render_tool(const ToolDrawable& t) {
  const Vec3& p = t.pose.position;
  const Vec3& a = t.pose.axis;
  const double len = t.shape.type == ToolShape::Type::Capsule ? t.shape.length : 0.0;
  return {{float(p.x()), float(p.y()), float(p.z()), float(t.shape.radius)},
          {float(a.x()), float(a.y()), float(a.z()), float(len)}};
}

uint32_t shade_layout(FrameLayout layout) {
  switch (layout) {
    case FrameLayout::SideBySide:
      return layout::kShadeLayoutSideBySide;
    case FrameLayout::Anaglyph:
      return layout::kShadeLayoutAnaglyph;
    case FrameLayout::Mono:
      break;
  }
  return layout::kShadeLayoutMono;
}

}  // namespace detail

using namespace detail;

SplatRenderer::Impl::~Impl() {
  if (ctx.abandoned()) return;  // unfinished work may read the sets
  const VkDevice device = ctx.device();
  if (pool != VK_NULL_HANDLE) ctx.fn().vkDestroyDescriptorPool(device, pool, nullptr);
  if (texture_layout != VK_NULL_HANDLE) {
    ctx.fn().vkDestroyDescriptorSetLayout(device, texture_layout, nullptr);
  }
}

// Set 1 of the accumulation pass (the texture and its sampler) and of the shading pass (the
// environment; the texture stands in for it until a scene sets one).
void SplatRenderer::Impl::create_texture_sets() {
  auto set = vk_struct<VkDescriptorSetLayoutCreateInfo>(
      VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO);
  set.bindingCount = 1;
  set.pBindings = &detail::kTextureBinding;
  VK_CHECK(ctx.fn().vkCreateDescriptorSetLayout(ctx.device(), &set, nullptr, &texture_layout));
  const VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 2};
  auto info = vk_struct<VkDescriptorPoolCreateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO);
  info.maxSets = 2;
  info.poolSizeCount = 1;
  info.pPoolSizes = &size;
  VK_CHECK(ctx.fn().vkCreateDescriptorPool(ctx.device(), &info, nullptr, &pool));
  const VkDescriptorSetLayout layouts[2] = {texture_layout, texture_layout};
  VkDescriptorSet sets[2] = {};
  auto alloc =
      vk_struct<VkDescriptorSetAllocateInfo>(VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO);
  alloc.descriptorPool = pool;
  alloc.descriptorSetCount = 2;
  alloc.pSetLayouts = layouts;
  VK_CHECK(ctx.fn().vkAllocateDescriptorSets(ctx.device(), &alloc, sets));
  texture_set = sets[0];
  environment_set = sets[1];
  write_texture_set(texture_set, texture);
  write_texture_set(environment_set, texture);
}

void SplatRenderer::Impl::write_texture_set(VkDescriptorSet set, const Texture& image) {
  const VkDescriptorImageInfo info{image.sampler(), image.view(),
                                   VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  auto write = vk_struct<VkWriteDescriptorSet>(VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET);
  write.dstSet = set;
  write.dstBinding = 0;
  write.descriptorCount = 1;
  write.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  write.pImageInfo = &info;
  ctx.fn().vkUpdateDescriptorSets(ctx.device(), 1, &write, 0, nullptr);
}

namespace detail {

// Each eye's range starts at a multiple of 64 pixels (256 bytes of depth), which satisfies
// every device's minStorageBufferOffsetAlignment.
uint64_t eye_stride_of(const FrameSetup& setup) {
  return (uint64_t(setup.eye_width) * setup.height + 63) / 64 * 64;
}

// Bytes of the accumulation buffer of all eyes (kAccumChannels ints per pixel).
uint64_t accum_bytes_of(const FrameSetup& setup) {
  return setup.eye_count() * eye_stride_of(setup) * layout::kAccumChannels * sizeof(int32_t);
}

}  // namespace detail

void SplatRenderer::Impl::ensure_targets(const FrameSetup& setup) {
  const uint32_t n = setup.eye_count(), width = setup.eye_width, height = setup.height;
  if (width == eye_width && height == eye_height && n <= eyes && setup.frame_width() == out_width) {
    return;
  }
  const uint64_t stride = eye_stride_of(setup);
  const uint64_t accum_bytes = accum_bytes_of(setup);
  eye_stride = static_cast<uint32_t>(stride);
  depth =
      gpu::Buffer(ctx, n * stride * sizeof(uint32_t), gpu::MemoryIntent::Device, "render depth");
  accum = gpu::Buffer(ctx, accum_bytes, gpu::MemoryIntent::Device, "render accumulation");
  accum_dirty = true;
  out_width = setup.frame_width();
  out_height = height;
  const uint64_t out_bytes = uint64_t(out_width) * out_height * 4;
  // Shared with the transfer queue, where a run's frames are copied out (render/frame_queue.h).
  frame = gpu::Buffer(ctx, out_bytes, gpu::MemoryIntent::Device, "render frame", 0,
                      /*with_transfer_queue=*/true);
  for (gpu::Buffer& r : readback) r = gpu::Buffer{};  // of the old size: made again on use
  eye_width = width;
  eye_height = height;
  eyes = n;
}

// Room for `slots` surfels: new buffers of max(slots, 2 x capacity) when they are too small
// (the whole table goes up again with the next frame; splats are rewritten every frame).
void SplatRenderer::Impl::grow(size_t slots) {
  slots = std::max<size_t>(slots, 1);
  if (slots <= capacity) return;
  const size_t grown = std::max(slots, 2 * capacity);
  surfels = gpu::Buffer(ctx, grown * sizeof(layout::SurfelStatic), gpu::MemoryIntent::Device,
                        "render surfels");
  surfel_staging = gpu::Buffer(ctx, grown * sizeof(layout::SurfelStatic), gpu::MemoryIntent::Upload,
                               "render surfels staging");
  splats =
      gpu::Buffer(ctx, grown * sizeof(layout::Splat), gpu::MemoryIntent::Device, "render splats");
  capacity = grown;
  dirty.assign((grown + kDirtyBlock - 1) / kDirtyBlock, 0);
  mark_dirty(0, table.size());
}

void SplatRenderer::Impl::mark_dirty(size_t slot) {
  dirty[slot / kDirtyBlock] = 1;
  any_dirty = true;
}

void SplatRenderer::Impl::mark_dirty(size_t first, size_t end) {
  if (first >= end) return;
  std::fill(dirty.begin() + long(first / kDirtyBlock),
            dirty.begin() + long((end - 1) / kDirtyBlock + 1), uint8_t{1});
  any_dirty = true;
}

bool SplatRenderer::Impl::record_surfel_upload(gpu::Recorder& rec) {
  if (!any_dirty) return false;
  constexpr size_t slot_bytes = sizeof(layout::SurfelStatic);
  auto* staging = static_cast<uint8_t*>(surfel_staging.mapped());
  for (size_t b = 0; b < dirty.size();) {
    if (!dirty[b]) {
      ++b;
      continue;
    }
    const size_t first = b * kDirtyBlock;
    while (b < dirty.size() && dirty[b]) dirty[b++] = 0;
    const size_t end = std::min(b * kDirtyBlock, table.size());
    if (first >= end) continue;
    const VkDeviceSize offset = first * slot_bytes, bytes = (end - first) * slot_bytes;
    std::memcpy(staging + offset, table.data() + first, bytes);
    rec.copy(surfel_staging, surfels, bytes, offset, offset);
  }
  any_dirty = false;
  return true;
}

void SplatRenderer::Impl::index_outer_slots() {
  if (!outer_offset.empty()) return;
  outer_offset.assign(size_t(table_phyxels) + 1, 0);
  for (size_t s = 0; s < outer_count; ++s)
    if (table[s].index < table_phyxels) ++outer_offset[table[s].index + 1];
  for (size_t k = 0; k < table_phyxels; ++k) outer_offset[k + 1] += outer_offset[k];
  outer_slot.resize(outer_offset.back());
  std::vector<uint32_t> next(outer_offset.begin(), outer_offset.end() - 1);
  for (size_t s = 0; s < outer_count; ++s)
    if (table[s].index < table_phyxels) outer_slot[next[table[s].index]++] = uint32_t(s);
}

layout::ShadePush SplatRenderer::Impl::shade_push(const FrameSetup& setup) const {
  const uint32_t n = setup.eye_count();
  layout::ShadePush shade{};
  shade.frustum0 = frustum_of(setup.eyes[0]);
  shade.frustum1 = frustum_of(setup.eyes[n - 1]);
  shade.near = {float(setup.eyes[0].frustum.near), float(setup.eyes[n - 1].frustum.near), 0, 0};
  shade.frame = {setup.eye_width, setup.height, shade_layout(setup.layout), eye_stride};
  if (has_environment) {
    shade.near.z = 1;
    shade.near.w = static_cast<float>(environment_area_ratio);
  }
  // Both eyes look the same way (parallel stereo): eye 0's rotation serves both.
  Eigen::Matrix4d eye_to_cube = Eigen::Matrix4d::Identity();
  eye_to_cube.topLeftCorner<3, 3>() =
      world_to_environment * setup.eyes[0].view.topLeftCorner<3, 3>().transpose();
  shade.eye_to_environment = to_mat4(eye_to_cube);
  return shade;
}

namespace {

bool same_view(const FrameSetup& a, const FrameSetup& b) {
  if (a.eye_width != b.eye_width || a.height != b.height || a.eye_count() != b.eye_count()) {
    return false;
  }
  for (uint32_t e = 0; e < a.eye_count(); ++e) {
    const Frustum &f = a.eyes[e].frustum, &g = b.eyes[e].frustum;
    if (a.eyes[e].view != b.eyes[e].view || f.left != g.left || f.right != g.right ||
        f.bottom != g.bottom || f.top != g.top || f.near != g.near || f.far != g.far) {
      return false;
    }
  }
  return true;
}

}  // namespace

// The backdrop layer of this view, when it is stale: the backdrop's splats through the
// visibility and accumulation passes alone (into layer_depth and the frame's accumulation
// buffer), then the shading pass per eye in the mono layout into layer_colour. Every frame
// starts from its depth; the shading pass shows its colour where no disc is.
void SplatRenderer::Impl::record_backdrop_layer(gpu::Recorder& rec, const FrameSetup& setup) {
  const VkDeviceSize depth_range = VkDeviceSize{eye_stride} * sizeof(uint32_t);
  const VkDeviceSize accum_range = depth_range * layout::kAccumChannels;
  const VkDeviceSize bytes = eyes * depth_range;
  if (!layer_depth || layer_depth.size() != bytes) {
    layer_depth = gpu::Buffer(ctx, bytes, gpu::MemoryIntent::Device, "render backdrop depth");
    layer_colour = gpu::Buffer(ctx, bytes, gpu::MemoryIntent::Device, "render backdrop colour");
    layer_stale = true;
  }
  if (!layer_stale && same_view(setup, layer_view)) return;
  const uint32_t n = setup.eye_count();
  rec.fill(layer_depth, layout::kDepthClear, 0, n * depth_range);
  rec.fill(accum, 0, 0, n * accum_range);
  rec.barrier();
  for (uint32_t e = 0; e < n; ++e) {
    gpu::dispatch(rec, visibility,
                  raster_push(setup.eyes[e], options.backdrop_epsilon, setup.eye_width,
                              setup.height, backdrop_count),
                  {{"Splats", backdrop}, {"Depth", layer_depth, e * depth_range, depth_range}},
                  raster_invocations(backdrop_count));
  }
  rec.barrier();
  ctx.fn().vkCmdBindDescriptorSets(rec.cmd(), VK_PIPELINE_BIND_POINT_COMPUTE, accumulate.layout(),
                                   layout::kRasterSetTexture, 1, &texture_set, 0, nullptr);
  for (uint32_t e = 0; e < n; ++e) {
    gpu::dispatch(rec, accumulate,
                  raster_push(setup.eyes[e], options.backdrop_epsilon, setup.eye_width,
                              setup.height, backdrop_count),
                  {{"Splats", backdrop},
                   {"Depth", layer_depth, e * depth_range, depth_range},
                   {"Accum", accum, e * accum_range, accum_range}},
                  raster_invocations(backdrop_count));
  }
  rec.barrier();
  ctx.fn().vkCmdBindDescriptorSets(rec.cmd(), VK_PIPELINE_BIND_POINT_COMPUTE, shade.layout(),
                                   layout::kShadeSetEnvironment, 1, &environment_set, 0, nullptr);
  for (uint32_t e = 0; e < n; ++e) {
    FrameSetup one = setup;
    one.layout = FrameLayout::Mono;
    one.eyes[0] = setup.eyes[e];
    const gpu::BufferRef eye_depth(layer_depth, e * depth_range, depth_range);
    gpu::dispatch(rec, shade, shade_push(one),
                  {{"Accum", accum, e * accum_range, accum_range},
                   {"Frame", layer_colour, e * depth_range, depth_range},
                   {"Depth", eye_depth},
                   {"BackdropDepth", eye_depth},
                   {"Backdrop", eye_depth}},
                  setup.eye_width * setup.height);
  }
  rec.barrier();
  layer_view = setup;
  layer_stale = false;
}

}  // namespace phyxel::render
