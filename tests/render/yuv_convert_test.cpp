// RGBA -> YUV 4:2:0 for --video (render/yuv_convert.h): BT.601 limited-range values of known
// colours, every sample within one level of the exact (double) formula, odd sides padded by
// repeating the last column and row, the same bytes from any number of threads, and sizes
// that do not fit refused.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/yuv_convert.h"

namespace phyxel::render {
namespace {

struct Planes {
  uint32_t width, height;
  std::vector<uint8_t> y, u, v;
  Planes(uint32_t w, uint32_t h)
      : width(w), height(h), y(size_t(w) * h), u(size_t(w / 2) * (h / 2)), v(u.size()) {}
  YuvPlanes view() {
    return {{y.data(), u.data(), v.data()},
            {int(width), int(width / 2), int(width / 2)},
            width,
            height};
  }
};

RgbaImage random_image(uint32_t w, uint32_t h, unsigned seed) {
  RgbaImage image(w, h);
  std::mt19937 rng(seed);
  for (uint8_t& c : image.pixels) c = static_cast<uint8_t>(rng() & 255);
  return image;
}

TEST(YuvConvert, KnownColoursHaveTheirBt601Values) {
  struct Case {
    int r, g, b, y, cb, cr;
  };
  // ITU-R BT.601 in 8 bits, limited range (the standard's table of the primaries).
  for (const Case& c : {Case{255, 255, 255, 235, 128, 128}, Case{0, 0, 0, 16, 128, 128},
                        Case{255, 0, 0, 81, 90, 240}, Case{0, 255, 0, 145, 54, 34},
                        Case{0, 0, 255, 41, 240, 110}, Case{200, 200, 200, 188, 128, 128}}) {
    EXPECT_EQ(luma_601(c.r, c.g, c.b), c.y) << c.r << " " << c.g << " " << c.b;
    EXPECT_EQ(cb_601(c.r, c.g, c.b), c.cb) << c.r << " " << c.g << " " << c.b;
    EXPECT_EQ(cr_601(c.r, c.g, c.b), c.cr) << c.r << " " << c.g << " " << c.b;
  }
}

TEST(YuvConvert, EverySampleIsWithinOneLevelOfTheExactFormula) {
  const RgbaImage image = random_image(64, 48, 7);
  Planes out(64, 48);
  rgba_to_yuv420(image, out.view());
  int worst = 0;
  for (uint32_t y = 0; y < 48; ++y) {
    for (uint32_t x = 0; x < 64; ++x) {
      const uint8_t* p = image.at(x, y);
      const double luma = 16 + (65.481 * p[0] + 128.553 * p[1] + 24.966 * p[2]) / 255;
      worst = std::max(worst, int(std::abs(out.y[y * 64 + x] - luma) + 0.5));
    }
  }
  for (uint32_t cy = 0; cy < 24; ++cy) {
    for (uint32_t cx = 0; cx < 32; ++cx) {
      double r = 0, g = 0, b = 0;
      for (uint32_t k = 0; k < 4; ++k) {
        const uint8_t* p = image.at(2 * cx + k % 2, 2 * cy + k / 2);
        r += p[0] / 4.0, g += p[1] / 4.0, b += p[2] / 4.0;
      }
      const double cb = 128 + (-37.797 * r - 74.203 * g + 112 * b) / 255;
      const double cr = 128 + (112 * r - 93.786 * g - 18.214 * b) / 255;
      worst = std::max(worst, int(std::abs(out.u[cy * 32 + cx] - cb) + 0.5));
      worst = std::max(worst, int(std::abs(out.v[cy * 32 + cx] - cr) + 0.5));
    }
  }
  EXPECT_LE(worst, 1);
}

TEST(YuvConvert, OddSidesRepeatTheLastColumnAndRow) {
  RgbaImage image(5, 3);
  for (uint32_t y = 0; y < 3; ++y)
    for (uint32_t x = 0; x < 5; ++x) {
      uint8_t* p = image.at(x, y);
      p[0] = p[1] = p[2] = static_cast<uint8_t>(40 * x + 10 * y), p[3] = 255;
    }
  Planes out(6, 4);
  rgba_to_yuv420(image, out.view());
  for (uint32_t y = 0; y < 4; ++y) {
    for (uint32_t x = 0; x < 6; ++x) {
      const uint8_t* p = image.at(std::min(x, 4u), std::min(y, 2u));
      EXPECT_EQ(out.y[y * 6 + x], luma_601(p[0], p[1], p[2])) << x << "," << y;
    }
  }
  // The last chroma sample of the padded corner is the corner pixel's own colour.
  const uint8_t* corner = image.at(4, 2);
  EXPECT_EQ(out.u[1 * 3 + 2], cb_601(corner[0], corner[1], corner[2]));
}

TEST(YuvConvert, AnyNumberOfThreadsGivesTheSameBytes) {
  const RgbaImage image = random_image(301, 517, 11);  // 259 row pairs: up to 16 bands
  Planes one(302, 518), many(302, 518);
  rgba_to_yuv420(image, one.view(), 1);
  for (unsigned threads : {2u, 7u, 16u}) {
    rgba_to_yuv420(image, many.view(), threads);
    EXPECT_EQ(one.y, many.y) << threads;
    EXPECT_EQ(one.u, many.u) << threads;
    EXPECT_EQ(one.v, many.v) << threads;
  }
}

TEST(YuvConvert, PlanesThatDoNotFitAreRefused) {
  const RgbaImage image = random_image(8, 8, 1);
  Planes small(6, 8), odd(9, 8), large(12, 8);
  EXPECT_THROW(rgba_to_yuv420(image, small.view()), std::invalid_argument);
  EXPECT_THROW(rgba_to_yuv420(image, odd.view()), std::invalid_argument);
  EXPECT_THROW(rgba_to_yuv420(image, large.view()), std::invalid_argument);
  EXPECT_THROW(rgba_to_yuv420(RgbaImage(), small.view()), std::invalid_argument);
}

}  // namespace
}  // namespace phyxel::render
