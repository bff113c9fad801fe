// A synthetic surgery clip for the video texture (the repository ships no real surgery video):
// pink tissue with vessels that pulse with a heartbeat (wider and darker at systole), the
// whole field swelling slightly, and two wet specular glints that ride on it. Deterministic:
// tools/make_video_clip writes scenes/video/pulsing_tissue.mp4 from it at build time, and the
// tests compare decoded frames with it.
#pragma once

#include <cstdint>
#include <filesystem>

#include "render/image.h"

namespace phyxel::render {

struct VideoClipOptions {
  uint32_t width = 256, height = 256;
  double fps = 30;
  int frames = 60;       // 2 s at 30 frames/s
  double pulse_s = 0.8;  // heartbeat period (75 beats/min): 2 s is 2.5 beats, so the raw clip
                         // jumps where it loops (what render.video_texture's loop_blend hides)
  bool glints = true;    // the specular glints (what repair_specular removes)
};

// Frame `index` (time index / fps) of the clip, opaque RGBA.
RgbaImage pulsing_tissue_frame(const VideoClipOptions& options, int index);

// Writes the clip as lossless H.264 (YUV 4:4:4, QP 0) in MP4 (render/video_writer.h). Throws
// std::runtime_error naming the file when it cannot.
void write_pulsing_tissue_clip(const std::filesystem::path& file, const VideoClipOptions& options);

}  // namespace phyxel::render
