// Render timing for `phyxel bench` (not a test): a stereo (or mono) frame of a spherical
// shell of about N surfels, eye size 1920 x 1080 by default, repeated after 0.5 s of warm-up
// frames (the GPU's clocks rise under load); median GPU time of the frame and of each pass
// (frames recorded 8 to a submission, so the GPU does not idle between them), and median host
// time per frame (one at a time: record, submit, wait, readback into an image). With `with_solver`,
// also the GPU solver on the same shell (breathing, no gravity, so it stays in view): its step rate
// alone, and with a frame rendered from its buffers every 1/60 s of its own stepping (what a live
// view at 60 frames/s costs the simulation).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/context.h"
#include "compute/timing.h"

namespace phyxel::bench {

struct RenderBenchOptions {
  uint32_t surfels = 100000;  // approximate
  uint32_t eye_width = 1920, height = 1080;
  bool stereo = true;  // side by side (two eyes); false: mono
  int frames = 10;     // timed frames, after one warm-up frame
  bool with_solver = false;
  // The video texture on (render/video_texture.h: the synthetic clip of render/video_clip.h,
  // 256 x 256, written to a temporary file, loop_blend 12, repair_specular) with the
  // procedural operating field as the environment; every timed frame shows the clip's next
  // frame (its upload recorded into the frame).
  bool video_texture = false;
};

struct RenderBenchResult {
  std::string device;
  uint32_t surfels = 0, phyxels = 0;
  uint32_t frame_width = 0, frame_height = 0, eyes = 0;
  int frames = 0;
  double median_frame_s = 0;                 // host wall time per frame
  double median_gpu_s = 0;                   // GPU time per frame, readback excluded
  double median_readback_s = 0;              // GPU time of the copy to host-visible memory
  double splats_per_s = 0;                   // surfels x eyes / median_gpu_s
  std::vector<gpu::PassTime> median_passes;  // "render clear", "render deform", ... (GPU ns)
  // with_solver: steps/s alone and while rendering (steps_per_frame steps between frames).
  double solver_steps_per_s = 0, solver_steps_per_s_rendering = 0, frames_per_s_rendering = 0;
  double solver_frame_gpu_s = 0;  // median GPU time of those frames, readback excluded
  int64_t steps_per_frame = 0;
  // video_texture: the decoding thread's time per frame (decode + RGBA) and its preprocessing
  // (specular repair, loop blend, mip chain), off the frame's path.
  double video_decode_s = 0, video_process_s = 0;
};

RenderBenchResult bench_render(gpu::Context& ctx, const RenderBenchOptions& options = {});

}  // namespace phyxel::bench
