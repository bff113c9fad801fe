// Render timing for `phyxel bench` (not a test): a stereo (or mono) frame of a spherical
// shell of about N surfels, eye size 1920 x 1080 by default, repeated; median host time per
// frame (record, submit, wait, readback included) and median GPU time per pass.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compute/context.h"
#include "compute/timing.h"

namespace phyxel::render {

struct RenderBenchOptions {
  uint32_t surfels = 100000;  // approximate
  uint32_t eye_width = 1920, height = 1080;
  bool stereo = true;  // side by side (two eyes); false: mono
  int frames = 10;     // timed frames, after one warm-up frame
};

struct RenderBenchResult {
  std::string device;
  uint32_t surfels = 0, phyxels = 0;
  uint32_t frame_width = 0, frame_height = 0, eyes = 0;
  int frames = 0;
  double median_frame_s = 0;                 // host wall time per frame
  double splats_per_s = 0;                   // surfels x eyes / median_frame_s
  std::vector<gpu::PassTime> median_passes;  // "render deform", "render eye 0", ... (GPU ns)
};

RenderBenchResult bench_render(gpu::Context& ctx, const RenderBenchOptions& options = {});

}  // namespace phyxel::render
