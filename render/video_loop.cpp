#include "render/video_loop.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace phyxel::render {

int loop_blend_frames(int frames, int blend) {
  return std::clamp(blend, 0, std::max(frames, 0) / 2);
}

int loop_length(int frames, int blend) {
  return frames - loop_blend_frames(frames, blend);
}

double loop_weight(int k, int blend) {
  if (blend <= 0 || k >= blend) return 1;
  return double(k + 1) / double(blend + 1);
}

void blend_loop_frame(RgbaImage& head, const RgbaImage& tail, int k, int blend) {
  if (head.width != tail.width || head.height != tail.height) {
    throw std::invalid_argument("blend_loop_frame: frames of different sizes");
  }
  const double w = loop_weight(k, blend);
  if (w >= 1) return;
  // In 1/256 steps, rounded: the same bytes on every machine.
  const int a = static_cast<int>(std::lround(w * 256)), b = 256 - a;
  for (size_t i = 0; i < head.pixels.size(); ++i) {
    head.pixels[i] = static_cast<uint8_t>((a * head.pixels[i] + b * tail.pixels[i] + 128) >> 8);
  }
}

std::vector<RgbaImage> loop_clip(const std::vector<RgbaImage>& frames, int blend) {
  const int n = static_cast<int>(frames.size());
  const int b = loop_blend_frames(n, blend), l = n - b;
  std::vector<RgbaImage> loop(frames.begin(), frames.begin() + l);
  for (int k = 0; k < b; ++k) blend_loop_frame(loop[size_t(k)], frames[size_t(l + k)], k, b);
  return loop;
}

}  // namespace phyxel::render
