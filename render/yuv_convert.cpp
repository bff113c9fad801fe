#include "render/yuv_convert.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

namespace phyxel::render {
namespace {

// BT.601, limited range: Y = 16 + (65.481 R + 128.553 G + 24.966 B) / 255, Cb = 128 +
// (-37.797 R - 74.203 G + 112 B) / 255, Cr = 128 + (112 R - 93.786 G - 18.214 B) / 255, as
// integers scaled by 2^16 / 255 (each chroma row sums to 0, luma's to 219 / 255 x 2^16).
constexpr int kYr = 16829, kYg = 33039, kYb = 6416;
constexpr int kUr = -9714, kUg = -19070, kUb = 28784;
constexpr int kVr = 28784, kVg = -24103, kVb = -4681;

uint8_t clamp_byte(int v) {
  return static_cast<uint8_t>(std::clamp(v, 0, 255));
}

// Chroma of the sum of four pixels' channels (each sum at most 1020): the mean's value.
uint8_t chroma4(int kr, int kg, int kb, int r4, int g4, int b4) {
  return clamp_byte((kr * r4 + kg * g4 + kb * b4 + (128 << 18) + (1 << 17)) >> 18);
}

// Rows [pair_begin, pair_end) x 2 of the output.
void convert_rows(const RgbaImage& image, const YuvPlanes& out, uint32_t pair_begin,
                  uint32_t pair_end) {
  const uint32_t last_x = image.width - 1, last_y = image.height - 1;
  for (uint32_t pair = pair_begin; pair < pair_end; ++pair) {
    const uint32_t y0 = std::min(2 * pair, last_y), y1 = std::min(2 * pair + 1, last_y);
    const uint8_t* rows[2] = {image.at(0, y0), image.at(0, y1)};
    uint8_t* luma[2] = {out.data[0] + size_t(2 * pair) * out.stride[0],
                        out.data[0] + size_t(2 * pair + 1) * out.stride[0]};
    uint8_t* cb = out.data[1] + size_t(pair) * out.stride[1];
    uint8_t* cr = out.data[2] + size_t(pair) * out.stride[2];
    for (uint32_t cx = 0; cx < out.width / 2; ++cx) {
      int r4 = 0, g4 = 0, b4 = 0;
      for (int dy = 0; dy < 2; ++dy) {
        for (uint32_t dx = 0; dx < 2; ++dx) {
          const uint8_t* p = rows[dy] + size_t(std::min(2 * cx + dx, last_x)) * 4;
          luma[dy][2 * cx + dx] = luma_601(p[0], p[1], p[2]);
          r4 += p[0];
          g4 += p[1];
          b4 += p[2];
        }
      }
      cb[cx] = chroma4(kUr, kUg, kUb, r4, g4, b4);
      cr[cx] = chroma4(kVr, kVg, kVb, r4, g4, b4);
    }
  }
}

}  // namespace

uint8_t luma_601(int r, int g, int b) {
  return clamp_byte((kYr * r + kYg * g + kYb * b + (16 << 16) + (1 << 15)) >> 16);
}
uint8_t cb_601(int r, int g, int b) {
  return chroma4(kUr, kUg, kUb, 4 * r, 4 * g, 4 * b);
}
uint8_t cr_601(int r, int g, int b) {
  return chroma4(kVr, kVg, kVb, 4 * r, 4 * g, 4 * b);
}

void rgba_to_yuv420(const RgbaImage& image, const YuvPlanes& out, unsigned threads) {
  const auto fits = [](uint32_t side, uint32_t padded) {
    return padded % 2 == 0 && (padded == side || padded == side + 1);
  };
  if (image.width == 0 || image.height == 0 ||
      image.pixels.size() != size_t(image.width) * image.height * 4 ||
      !fits(image.width, out.width) || !fits(image.height, out.height))
    throw std::invalid_argument("rgba_to_yuv420: a " + std::to_string(image.width) + " x " +
                                std::to_string(image.height) + " image does not fit planes of " +
                                std::to_string(out.width) + " x " + std::to_string(out.height));
  const uint32_t pairs = out.height / 2;
  if (threads == 0) threads = std::clamp(std::thread::hardware_concurrency(), 1u, 16u);
  // At least 16 row pairs a band: below that a thread costs more than it saves.
  threads = std::clamp(pairs / 16, 1u, threads);
  std::vector<std::thread> band;
  band.reserve(threads - 1);
  unsigned started = 1;  // bands a thread was started for (band 0 is this thread's)
  try {
    for (; started < threads; ++started)
      band.emplace_back(convert_rows, std::cref(image), std::cref(out), pairs * started / threads,
                        pairs * (started + 1) / threads);
  } catch (const std::system_error&) {  // no thread to be had: this thread does the rest
  }
  convert_rows(image, out, 0, pairs / threads);
  if (started < threads) convert_rows(image, out, pairs * started / threads, pairs);
  for (std::thread& t : band) t.join();
}

}  // namespace phyxel::render
