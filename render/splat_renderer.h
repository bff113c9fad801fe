// The splat renderer: surfels of the surface phyxels drawn as perspective-correct textured
// discs in three passes after Botsch et al. 2005 ("High-quality surface splatting on today's
// GPUs"), from the four solver buffers of RenderInputs. Every pass is a compute dispatch (a
// splat rasteriser in the manner of Schuetz et al. 2021), so it runs on any queue that the
// solver's does and uses every shader core (on the H100 only a few can rasterise):
//
//   clear              depth to far (with a backdrop: its layer's depth, the layer drawn
//                      first when the view changed), accumulators to 0
//   deform             centre x0 + u, normal (I + grad u)^-T n, texture gradients, radius
//   per eye, with tools only (set_tools), one invocation per pixel:
//     0 tools          ray cast of every tool (ball or capsule); the nearest writes its exact
//                      depth (atomicMin, the splats' encoding) and its normal
//   per eye, one invocation per splat over the pixels its disc may cover:
//     1 visibility     atomicMin of the nearest disc's depth + epsilon (ray-disc per pixel)
//     2 accumulation   fixed-point atomicAdd of colour x w, w, normal x w of the discs within
//                      epsilon (exact integer sums: the image does not depend on their order)
//   3 shading          per frame pixel: normalisation, deferred Phong, the frame layout;
//                      steel where a tool won the depth test and no splat is in front of it
//   then the frame is copied to a host-visible buffer.
//
// Mono: one eye, width x height. Side by side: the two eyes next to each other in one image
// twice as wide (the left eye on the left unless swap_eyes). Anaglyph: width x height, red
// from the left eye, green and blue from the right.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "compute/pipeline.h"
#include "compute/timing.h"
#include "render/camera.h"
#include "render/image.h"
#include "render/surfels.h"
#include "render/tool_raycast.h"

namespace phyxel::render {

// Colour of pixels that no splat covers (as render/shaders/splat_common.glsl).
inline constexpr uint8_t kBackground[3] = {20, 23, 28};

enum class FrameLayout { Mono, SideBySide, Anaglyph };

// What to draw: the eyes (eyes[0] goes to the left half / red channel) and the size.
struct FrameSetup {
  FrameLayout layout = FrameLayout::Mono;
  uint32_t eye_width = 256, height = 256;
  std::array<EyeView, 2> eyes{};  // eyes[1] unused for Mono
  uint32_t eye_count() const { return layout == FrameLayout::Mono ? 1u : 2u; }
  uint32_t frame_width() const {
    return layout == FrameLayout::SideBySide ? 2 * eye_width : eye_width;
  }
};

// The frame setup of a camera for a render mode (Mono or Stereo) and the scene's settings
// (size, stereo layout, IPD, focal distance, swap_eyes).
FrameSetup make_frame_setup(const Camera& camera, const RenderSettings& settings,
                            RenderSettings::Mode mode);

struct RendererOptions {
  // Splat radius = radius_scale x the phyxel's splat_radius (0.8 spacing from the sampler,
  // enough for a lattice-aligned plane). On curved surfaces the lattice's surface phyxels
  // lie up to ~0.9 spacing below the surface, and discs tangent to the surface leave slits
  // between the steps of that staircase when seen obliquely; 1.5 (1.2 spacing) closes them
  // from every direction (splat_render_test: the hole test fails below about 1.4).
  float radius_scale = 1.5f;
  float epsilon = 1.0f;      // visibility offset, in splat radii
  float max_stretch = 4.0f;  // splat radius growth limit under tangential stretch
  // Visibility offset of the backdrop's discs, in their radii: they are large (a drape's
  // spacing is centimetres) and mostly flat, so half a radius joins neighbours without
  // blending the drape into tissue that lies just above it.
  float backdrop_epsilon = 0.5f;
  // One 64-bit atomicAdd per pair of accumulation channels where the device has
  // shaderBufferInt64Atomics (the same image as a 32-bit add per channel, render_layout.h);
  // false forces the 32-bit adds, as does the measurement switch $PHYXEL_ACCUM_INT64 "0".
  bool int64_atomics = true;
};

class SplatRenderer {
 public:
  // Uploads the surfel table and the texture (with mipmaps). Throws VulkanError when the
  // device lacks what the passes need, std::invalid_argument on an empty texture.
  SplatRenderer(gpu::Context& ctx, const SurfelTable& surfels, const RgbaImage& texture,
                const RendererOptions& options = {});
  ~SplatRenderer();
  SplatRenderer(const SplatRenderer&) = delete;
  SplatRenderer& operator=(const SplatRenderer&) = delete;

  // The tools drawn by the frames recorded from now on (none by default: then the tool pass
  // records nothing and frames are as without tools). Each needs radius > 0 and a unit axis;
  // throws std::invalid_argument otherwise. record() copies them into a mapped buffer, so, as
  // for the frame itself, the previous frame must have finished before the next is recorded.
  void set_tools(std::vector<ToolDrawable> tools);
  const std::vector<ToolDrawable>& tools() const;

  // The surroundings (render/environment_map.h, the paper's eqs 33-34), from the next frame
  // on: a square image on a cube at infinity whose frame is `world_to_cube` (rows: the cube's
  // x, y, z in world coordinates; environment_basis of the scene's camera), area ratio K of
  // its top face. Pixels that nothing covers show it, and surfels with a mirror level (flags,
  // kSurfelMirrorShift) reflect it. None by default (the plain kBackground). Waits for the
  // device. Throws std::invalid_argument for an image that is not square or K <= 0.
  void set_environment(const RgbaImage& image, const Eigen::Matrix3d& world_to_cube,
                       double area_ratio);

  // A new texture from the next frame on, as a mip chain (vk_images.h mip_chain; a video
  // frame's, render/video_texture.h). Of the current texture's sizes it is copied into its
  // staging buffer and the copy is recorded into the next frame (no extra submission; the
  // previous frame must have finished, as render() and the callers of record() ensure); of
  // other sizes the texture is made anew (waits for the device).
  void set_texture(const std::vector<RgbaImage>& levels);
  // The backdrop (render/backdrop.h: bake_backdrop): static splats with their colour baked
  // (kSplatBaked in normal.w; the deform pass never sees them), uploaded once. They are drawn
  // into a layer once per view (when the eyes, frusta or size change, or after this call or
  // set_environment): its depth starts each frame's depth buffer and its shaded colour shows
  // where no disc is (unless a tool is nearer). An empty list removes it. Waits for the
  // device. Throws std::invalid_argument for a splat without kSplatBaked or with a radius
  // that is not finite and > 0.
  void set_backdrop(const std::vector<layout::Splat>& splats);
  uint32_t backdrop_count() const;

  // Renders one frame of the current state of `inputs` and returns it (waits for the GPU).
  RgbaImage render(const RenderInputs& inputs, const FrameSetup& setup);

  // The same in steps, for callers that submit themselves: record() records the frame into
  // `rec` (with a timestamp per pass when `timer` is given) ending with its copy into
  // read-back slot `slot`, and read_frame(slot) returns the pixels after rec's submission
  // has completed. Two slots let one frame be read on another thread while the next is drawn
  // (render/frame_queue.h); a slot is made on its first use and again after a size change.
  // `copy`: where the copy into the slot goes instead of `rec` (a Recorder of the transfer
  // queue, whose submission waits on a semaphore that rec's signals); its pixels are then read
  // after copy's submission has completed.
  static constexpr uint32_t kReadbackSlots = 2;
  void record(gpu::Recorder& rec, const RenderInputs& inputs, const FrameSetup& setup,
              gpu::PassTimer* timer = nullptr, uint32_t slot = 0, gpu::Recorder* copy = nullptr);
  // The same in two submissions: `deform` gets the table's edits and the deform pass (the only
  // commands that read `inputs`; submit it on the solver's queue, signalling a semaphore) and
  // `raster` the rest, from clearing the targets on (submitted after, waiting on that
  // semaphore; on another queue it runs beside the solver's next passes).
  void record_split(gpu::Recorder& deform, gpu::Recorder& raster, const RenderInputs& inputs,
                    const FrameSetup& setup, uint32_t slot = 0, gpu::Recorder* copy = nullptr);
  // The table's edits and the deform pass alone (FrameQueue's $PHYXEL_FRAME_DRAW "0": what a
  // frame costs a run without its drawing).
  void record_deform(gpu::Recorder& rec, const RenderInputs& inputs);
  // false: frames end with the shading pass, nothing copied into a read-back slot
  // (FrameQueue's $PHYXEL_FRAME_COPY "0": what the copy costs a run).
  void set_readback(bool on);
  RgbaImage read_frame(uint32_t slot = 0) const;
  // The deformed splats of the last frame (surface surfels first, then the cut faces in the
  // order they were added): a blocking download, for tests.
  std::vector<layout::Splat> read_splats() const;

  // Why a frame of `setup` cannot be rendered on this device (an empty frame, a side over
  // max_frame_side(), buffers over maxStorageBufferRange), or "" when it can.
  std::string frame_error(const FrameSetup& setup) const;

  // Cut faces (render/cut_surfels.h): adds the given surfels (kSurfelCutFace set, radius at
  // rest before radius_scale) to those drawn, or replaces the cut-face surfel of a phyxel that
  // has one. The slots written are uploaded with the next frame (record), which must not be
  // recorded while an earlier frame is still in flight; the surfel and splat buffers double
  // when they run out (call between frames then), so the table built by the constructor is
  // never rebuilt. Throws std::invalid_argument for a surfel that is no cut face or whose
  // phyxel the table does not have.
  void update_cut_surfels(const std::vector<layout::SurfelStatic>& faces);

  // Removed phyxels (aspiration): every surfel of theirs, outer or cut face, gets radius 0
  // (drawn nowhere), uploaded with the next frame as above. Never waits for the GPU.
  void hide_phyxels(const std::vector<uint32_t>& phyxels);

  // The surfel table as the next frame draws it (outer surface, then the cut faces).
  const std::vector<layout::SurfelStatic>& surfels() const;

  uint32_t surfel_count() const;      // outer surface and cut faces
  uint32_t cut_surfel_count() const;  // cut faces
  // The largest frame side the renderer accepts (maxImageDimension2D and viewport limits, as
  // a window could show it).
  uint32_t max_frame_side() const;
  // Whether the accumulation adds pairs of channels with 64-bit atomics
  // (RendererOptions::int64_atomics and the device's shaderBufferInt64Atomics).
  bool int64_atomics() const;

 private:
  struct Impl;
  void record_frame(gpu::Recorder& deform, gpu::Recorder& rec, const RenderInputs& inputs,
                    const FrameSetup& setup, gpu::PassTimer* timer, uint32_t slot,
                    gpu::Recorder* copy);
  std::unique_ptr<Impl> impl_;
};

}  // namespace phyxel::render
