// The video texture's preprocessing on synthetic frames with known answers (the paper's
// section VI): eq 31's threshold, a planted specular spot found, magnified 1.1x about its centre
// of mass and repaired from its surroundings, and the loop blend of eq 32 that leaves no seam
// where the clip restarts.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "render/specular_repair.h"
#include "render/video_loop.h"

namespace phyxel::render {
namespace {

// Smooth tissue: pink, slowly varying (the repair from the ring is then close to the truth).
RgbaImage tissue(uint32_t w, uint32_t h, double phase = 0) {
  RgbaImage image(w, h);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const double s = std::sin(0.05 * x + phase) * std::cos(0.04 * y - 0.5 * phase);
      uint8_t* p = image.at(x, y);
      p[0] = uint8_t(190 + 30 * s);
      p[1] = uint8_t(95 + 25 * s);
      p[2] = uint8_t(100 + 20 * s);
      p[3] = 255;
    }
  return image;
}

// A white glint of radius r at (cx, cy): inside the disc white, a one-pixel soft rim.
void plant_spot(RgbaImage& image, double cx, double cy, double r) {
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = 0; x < image.width; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      const double w = std::clamp(r + 0.5 - d, 0.0, 1.0);
      uint8_t* p = image.at(x, y);
      for (int c = 0; c < 3; ++c) p[c] = uint8_t(std::lround(p[c] + (250 - p[c]) * w));
    }
}

TEST(SpecularRepair, OtsuThresholdOfEquation31SplitsTwoLevels) {
  std::array<uint64_t, 256> h{};
  h[60] = 900;
  h[70] = 500;
  h[230] = 40;
  h[240] = 20;
  const int k = otsu_threshold(h);
  EXPECT_GE(k, 70);
  EXPECT_LT(k, 230);
  // Brute force of eq 31 with the total mean g_T where the paper prints g_s (Otsu's criterion;
  // with g_s, the mean of U_s, the numerator is 0 for every k: docs/decisions.md): the maximum
  // over k of (P_s g_T - g(k))^2 / (P_s P_b).
  double best = -1;
  int k_best = -1;
  const double n = 1460, g_t = (60 * 900 + 70 * 500 + 230 * 40 + 240 * 20) / n;
  for (int t = 0; t < 255; ++t) {
    double p = 0, g = 0;
    for (int i = 0; i <= t; ++i) p += h[i] / n, g += i * h[i] / n;
    if (p <= 0 || p >= 1) continue;
    const double v = (p * g_t - g) * (p * g_t - g) / (p * (1 - p));
    if (v > best) best = v, k_best = t;
  }
  EXPECT_EQ(k, k_best);
  EXPECT_EQ(otsu_threshold({}), 0);
}

TEST(SpecularRepair, PlantedSpotIsFoundAndRepaired) {
  const uint32_t w = 128, h = 96;
  const RgbaImage clean = tissue(w, h);
  RgbaImage frame = clean;
  const double cx = 40, cy = 50, r = 6;
  plant_spot(frame, cx, cy, r);
  // Found: every pixel well inside the disc, nothing away from it.
  const std::vector<uint8_t> mask = specular_mask(frame);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      if (d < r - 1) {
        EXPECT_EQ(mask[y * w + x], 1) << x << ", " << y;
      }
      if (d > r + 1) {
        EXPECT_EQ(mask[y * w + x], 0) << x << ", " << y;
      }
    }
  // Nothing in tissue without glints.
  const std::vector<uint8_t> none = specular_mask(clean);
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
  RgbaImage untouched = clean;
  EXPECT_EQ(repair_specular(untouched), 0u);
  EXPECT_EQ(untouched.pixels, clean.pixels);

  // Repaired: close to the tissue under the glint; everything outside U_s' as it was.
  const std::vector<uint8_t> region = magnify_spots(mask, w, h);
  const size_t repaired = repair_specular(frame);
  EXPECT_EQ(repaired, size_t(std::count(region.begin(), region.end(), 1)));
  int worst = 0;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const double d = std::hypot(x + 0.5 - cx, y + 0.5 - cy);
      for (int c = 0; c < 3; ++c) {
        const int diff = std::abs(frame.at(x, y)[c] - clean.at(x, y)[c]);
        if (region[y * w + x] != 0) {
          worst = std::max(worst, diff);
        } else if (d > r + 1) {
          EXPECT_EQ(diff, 0) << x << ", " << y;
        }
      }
    }
  EXPECT_LE(worst, 8) << "the repaired spot differs from the tissue under it by up to " << worst;
  const std::vector<uint8_t> left = specular_mask(frame);
  EXPECT_EQ(std::count(left.begin(), left.end(), 1), 0) << "no glint left";
}

TEST(SpecularRepair, SpotsAreMagnifiedAboutTheirOwnCentreOfMass) {
  const uint32_t w = 80, h = 60;
  std::vector<uint8_t> mask(w * h, 0);
  for (uint32_t y = 10; y < 30; ++y)  // a 20 x 20 square, centre of mass (19.5, 19.5)
    for (uint32_t x = 10; x < 30; ++x) mask[y * w + x] = 1;
  for (uint32_t y = 40; y < 52; ++y)  // and a 12 x 12 one far away, centre (65.5, 45.5)
    for (uint32_t x = 60; x < 72; ++x) mask[y * w + x] = 1;
  const std::vector<uint8_t> out = magnify_spots(mask, w, h, 1.1);
  auto box = [&](uint32_t x0, uint32_t x1) {  // columns x0 ... x1 of out: extent and centre
    int lo = 1 << 20, hi = -1, top = 1 << 20, bottom = -1;
    double sx = 0, sy = 0, n = 0;
    for (uint32_t y = 0; y < h; ++y)
      for (uint32_t x = x0; x <= x1; ++x)
        if (out[y * w + x] != 0) {
          lo = std::min(lo, int(x)), hi = std::max(hi, int(x));
          top = std::min(top, int(y)), bottom = std::max(bottom, int(y));
          sx += x, sy += y, n += 1;
        }
    return std::array<double, 6>{double(lo),     double(hi), double(top),
                                 double(bottom), sx / n,     sy / n};
  };
  const auto a = box(0, 45);
  // 20 x 1.1 = 22 pixels wide, plus the one-pixel rim on each side: 24.
  EXPECT_EQ(a[1] - a[0] + 1, 24);
  EXPECT_EQ(a[3] - a[2] + 1, 24);
  EXPECT_NEAR(a[4], 19.5, 1e-9);  // registered: the same centre of mass
  EXPECT_NEAR(a[5], 19.5, 1e-9);
  const auto b = box(46, 79);
  EXPECT_EQ(b[1] - b[0] + 1, 16);  // 12 x 1.1 = 13.2: 14 pixels, plus the rim
  EXPECT_NEAR(b[4], 65.5, 1e-9);
  EXPECT_NEAR(b[5], 45.5, 1e-9);
}

TEST(SpecularRepair, FillRegionFromTheRingIsExactOnAFlatColour) {
  RgbaImage image(32, 32);
  for (size_t i = 0; i < image.pixels.size(); i += 4)
    image.pixels[i] = 200, image.pixels[i + 1] = 90, image.pixels[i + 2] = 80,
    image.pixels[i + 3] = 255;
  const RgbaImage flat = image;
  std::vector<uint8_t> region(32 * 32, 0);
  for (uint32_t y = 5; y < 20; ++y)
    for (uint32_t x = 8; x < 25; ++x) region[y * 32 + x] = 1, image.at(x, y)[0] = 0;
  fill_region(image, region);
  EXPECT_EQ(image.pixels, flat.pixels);
}

// A clip of a periodic motion whose period (16.4 frames) does not divide its length: the raw
// loop jumps where it restarts.
std::vector<RgbaImage> periodic_clip(int frames) {
  std::vector<RgbaImage> clip;
  for (int k = 0; k < frames; ++k) {
    RgbaImage f(24, 16);
    for (uint32_t y = 0; y < f.height; ++y)
      for (uint32_t x = 0; x < f.width; ++x) {
        const double v = 0.5 + 0.4 * std::sin(2 * std::numbers::pi * k / 16.4 + 0.3 * x + 0.2 * y);
        uint8_t* p = f.at(x, y);
        p[0] = p[1] = p[2] = uint8_t(std::lround(255 * v));
        p[3] = 255;
      }
    clip.push_back(std::move(f));
  }
  return clip;
}

double mean_abs_difference(const RgbaImage& a, const RgbaImage& b) {
  double sum = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) sum += std::abs(a.pixels[i] - b.pixels[i]);
  return sum / double(a.pixels.size());
}

// Frame-to-frame differences of a looping sequence: [k] from frame k to k + 1, the last one
// across the restart (from the last frame to the first).
std::vector<double> loop_steps(const std::vector<RgbaImage>& loop) {
  std::vector<double> d;
  for (size_t k = 0; k < loop.size(); ++k)
    d.push_back(mean_abs_difference(loop[k], loop[(k + 1) % loop.size()]));
  return d;
}

TEST(VideoLoop, BlendedLoopHasNoSeamAboveTheFrameToFrameDifferenceElsewhere) {
  const std::vector<RgbaImage> clip = periodic_clip(90);
  const std::vector<double> raw = loop_steps(clip);
  const double raw_elsewhere = *std::max_element(raw.begin(), raw.end() - 1);
  EXPECT_GT(raw.back(), 3 * raw_elsewhere) << "the raw clip must jump for the test to mean much";

  const int blend = 20;
  const std::vector<RgbaImage> loop = loop_clip(clip, blend);
  ASSERT_EQ(loop.size(), 70u);
  const std::vector<double> steps = loop_steps(loop);
  const double elsewhere = *std::max_element(steps.begin(), steps.end() - 1);
  std::printf(
      "mean |difference| per frame: raw seam %.1f, raw elsewhere <= %.1f; blended seam "
      "%.1f, blended elsewhere <= %.1f\n",
      raw.back(), raw_elsewhere, steps.back(), elsewhere);
  EXPECT_LE(steps.back(), elsewhere) << "the seam: " << steps.back();
  EXPECT_LE(steps.back(), 1.1 * raw_elsewhere);
  // Eq 32's weights: w_k f_k + (1 - w_k) f_{L+k}, w_k = (k + 1) / (B + 1).
  EXPECT_DOUBLE_EQ(loop_weight(0, blend), 1.0 / 21);
  EXPECT_DOUBLE_EQ(loop_weight(19, blend), 20.0 / 21);
  EXPECT_DOUBLE_EQ(loop_weight(20, blend), 1.0);
  EXPECT_EQ(loop[30].pixels, clip[30].pixels) << "frames past the blend are the clip's own";
  const uint8_t head = clip[5].pixels[0], tail = clip[75].pixels[0];
  EXPECT_NEAR(loop[5].pixels[0], (6.0 * head + 15.0 * tail) / 21, 1.0);
  EXPECT_EQ(loop_blend_frames(90, 1000), 45) << "at most half the clip";
  EXPECT_EQ(loop_length(90, 0), 90);
}

}  // namespace
}  // namespace phyxel::render
