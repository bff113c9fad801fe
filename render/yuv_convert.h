// RGBA frames to the YUV 4:2:0 planes that H.264 takes (render/video_writer.h), split over
// threads: a stereo 1080p frame (3840 x 1080) is 4.1 million pixels, and libswscale converts
// it on one thread in about the time x264's frame threads encode one, which halved --video's
// rate. BT.601 coefficients in the limited ("TV", 16-235) range, as libswscale's default and
// as the MP4 is tagged; each chroma sample is the mean of its 2 x 2 pixels' colours.
#pragma once

#include <array>
#include <cstdint>

#include "render/image.h"

namespace phyxel::render {

// Y, U and V planes of a frame of width x height (both even), with their row strides.
struct YuvPlanes {
  std::array<uint8_t*, 3> data{};
  std::array<int, 3> stride{};
  uint32_t width = 0, height = 0;
};

// The BT.601 limited-range value of one colour (exact integer arithmetic, rounded).
uint8_t luma_601(int r, int g, int b);
uint8_t cb_601(int r, int g, int b);
uint8_t cr_601(int r, int g, int b);

// Converts `image` into `out`. `out` may be larger than the image by one column and one row
// (4:2:0 needs even sides): the image's last column and row are then repeated. `threads`
// bands of rows (0: one per hardware thread, at most 16) give the same bytes as one.
// Throws std::invalid_argument when the sizes do not fit.
void rgba_to_yuv420(const RgbaImage& image, const YuvPlanes& out, unsigned threads = 0);

}  // namespace phyxel::render
