// make_video_clip OUT.mp4 [FRAMES [SIZE]]: writes the synthetic surgery clip of
// render/video_clip.h (pulsing tissue with vessels and two specular glints, 30 frames/s,
// lossless H.264 in MP4) for render.video_texture. The build runs it to make
// scenes/video/pulsing_tissue.mp4 (60 frames of 256 x 256; git-ignored).
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "render/video_clip.h"

int main(int argc, char** argv) {
  if (argc < 2 || argc > 4) {
    std::fprintf(stderr,
                 "usage: make_video_clip OUT.mp4 [FRAMES (2 ... 3000, default 60) [SIZE (16 ... "
                 "2048, default 256)]]\n");
    return 2;
  }
  phyxel::render::VideoClipOptions options;
  if (argc >= 3) {
    const long frames = std::strtol(argv[2], nullptr, 10);
    if (frames < 2 || frames > 3000) {
      std::fprintf(stderr, "make_video_clip: FRAMES %s: allowed 2 ... 3000\n", argv[2]);
      return 2;
    }
    options.frames = static_cast<int>(frames);
  }
  if (argc == 4) {
    const long size = std::strtol(argv[3], nullptr, 10);
    if (size < 16 || size > 2048) {
      std::fprintf(stderr, "make_video_clip: SIZE %s: allowed 16 ... 2048\n", argv[3]);
      return 2;
    }
    options.width = options.height = static_cast<uint32_t>(size);
  }
  try {
    phyxel::render::write_pulsing_tissue_clip(argv[1], options);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_video_clip: %s\n", e.what());
    return 1;
  }
  return 0;
}
