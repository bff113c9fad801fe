#include "render/specular_repair.h"

#include <algorithm>
#include <cmath>

namespace phyxel::render {

int otsu_threshold(const std::array<uint64_t, 256>& histogram) {
  double total = 0, grey_sum = 0;
  for (int i = 0; i < 256; ++i) {
    total += double(histogram[i]);
    grey_sum += double(i) * double(histogram[i]);
  }
  if (total == 0) return 0;
  const double g_total = grey_sum / total;  // the mean grey level
  double p_s = 0, g = 0, best = -1;
  int k_best = 0;
  for (int k = 0; k < 255; ++k) {
    p_s += double(histogram[k]) / total;            // P_s(k): probability of a level <= k
    g += double(k) * double(histogram[k]) / total;  // g(k): the cumulative grey value
    const double p_b = 1 - p_s;
    if (p_s <= 0 || p_b <= 1e-12) continue;
    const double between = (p_s * g_total - g) * (p_s * g_total - g) / (p_s * p_b);  // eq 31
    if (between > best) {
      best = between;
      k_best = k;
    }
  }
  return k_best;
}

std::vector<uint8_t> specular_mask(const RgbaImage& image, const SpecularOptions& options) {
  const size_t n = size_t(image.width) * image.height;
  std::vector<uint8_t> grey(n), mask(n, 0);
  std::array<uint64_t, 256> histogram{};
  for (size_t i = 0; i < n; ++i) {
    const uint8_t* p = &image.pixels[4 * i];
    grey[i] = std::min({p[0], p[1], p[2]});
    ++histogram[grey[i]];
  }
  const int k = std::max(otsu_threshold(histogram), options.min_level);
  size_t count = 0;
  for (size_t i = 0; i < n; ++i) {
    mask[i] = grey[i] > k ? 1 : 0;
    count += mask[i];
  }
  if (double(count) > options.max_fraction * double(n)) std::fill(mask.begin(), mask.end(), 0);
  return mask;
}

std::vector<uint8_t> magnify_spots(const std::vector<uint8_t>& mask, uint32_t width,
                                   uint32_t height, double scale) {
  std::vector<uint8_t> out(mask.size(), 0);
  std::vector<int> label(mask.size(), -1);
  std::vector<size_t> stack, pixels;
  const auto w = static_cast<int>(width), h = static_cast<int>(height);
  auto inside = [&](double x, double y) {  // U_s bilinearly interpolated at (x, y)
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    auto at = [&](int xx, int yy) -> double {
      if (xx < 0 || yy < 0 || xx >= w || yy >= h) return 0;
      return mask[size_t(yy) * width + size_t(xx)] != 0 ? 1 : 0;
    };
    const double v = (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
                     fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
    return v >= 0.5;
  };
  int spots = 0;
  for (size_t seed = 0; seed < mask.size(); ++seed) {
    if (mask[seed] == 0 || label[seed] >= 0) continue;
    // One 8-connected spot: its pixels, bounding box and centre of mass.
    pixels.clear();
    stack.assign(1, seed);
    label[seed] = spots;
    double cx = 0, cy = 0;
    int x_lo = w, x_hi = -1, y_lo = h, y_hi = -1;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      pixels.push_back(i);
      const int x = int(i % width), y = int(i / width);
      cx += x;
      cy += y;
      x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
      y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
          const size_t j = size_t(ny) * width + size_t(nx);
          if (mask[j] != 0 && label[j] < 0) {
            label[j] = spots;
            stack.push_back(j);
          }
        }
    }
    cx /= double(pixels.size());
    cy /= double(pixels.size());
    // U_s' about the same centre of mass: p is inside when c + (p - c) / scale is in U_s.
    const double grow = scale - 1;
    const int mx = int(std::ceil((x_hi - x_lo + 1) * grow)) + 2;
    const int my = int(std::ceil((y_hi - y_lo + 1) * grow)) + 2;
    for (int y = std::max(0, y_lo - my); y <= std::min(h - 1, y_hi + my); ++y)
      for (int x = std::max(0, x_lo - mx); x <= std::min(w - 1, x_hi + mx); ++x) {
        if (inside(cx + (x - cx) / scale, cy + (y - cy) / scale)) {
          out[size_t(y) * width + size_t(x)] = 1;
        }
      }
    for (const size_t i : pixels) out[i] = 1;
    ++spots;
  }
  // The rim: one pixel around (a glint's anti-aliased edge is brighter than the tissue).
  std::vector<uint8_t> grown = out;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (out[size_t(y) * width + size_t(x)] == 0) continue;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx >= 0 && ny >= 0 && nx < w && ny < h) grown[size_t(ny) * width + size_t(nx)] = 1;
        }
    }
  return grown;
}

void fill_region(RgbaImage& image, const std::vector<uint8_t>& region) {
  const auto w = static_cast<int>(image.width), h = static_cast<int>(image.height);
  std::vector<uint8_t> known(region.size());
  size_t unknown = 0;
  int x_lo = w, x_hi = -1, y_lo = h, y_hi = -1;  // the region's bounding box
  for (size_t i = 0; i < region.size(); ++i) {
    known[i] = region[i] == 0 ? 1 : 0;
    if (region[i] == 0) continue;
    ++unknown;
    const int x = int(i % image.width), y = int(i / image.width);
    x_lo = std::min(x_lo, x), x_hi = std::max(x_hi, x);
    y_lo = std::min(y_lo, y), y_hi = std::max(y_hi, y);
  }
  if (unknown == region.size()) return;
  std::vector<size_t> ring;
  std::vector<std::array<uint8_t, 4>> value;
  while (unknown > 0) {
    // The ring: unknown pixels next to known ones; each the mean of its known neighbours.
    ring.clear();
    value.clear();
    for (int y = y_lo; y <= y_hi; ++y)
      for (int x = x_lo; x <= x_hi; ++x) {
        const size_t i = size_t(y) * image.width + size_t(x);
        if (known[i] != 0) continue;
        int sum[4] = {0, 0, 0, 0}, n = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx, ny = y + dy;
            if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
            const size_t j = size_t(ny) * image.width + size_t(nx);
            if (known[j] == 0) continue;
            for (int c = 0; c < 4; ++c) sum[c] += image.pixels[4 * j + c];
            ++n;
          }
        if (n == 0) continue;
        std::array<uint8_t, 4> v{};
        for (int c = 0; c < 4; ++c) v[c] = static_cast<uint8_t>((sum[c] + n / 2) / n);
        ring.push_back(i);
        value.push_back(v);
      }
    for (size_t k = 0; k < ring.size(); ++k) {
      std::copy(value[k].begin(), value[k].end(), &image.pixels[4 * ring[k]]);
      known[ring[k]] = 1;
    }
    unknown -= ring.size();
  }
}

size_t repair_specular(RgbaImage& image, const SpecularOptions& options) {
  const std::vector<uint8_t> mask = specular_mask(image, options);
  if (std::find(mask.begin(), mask.end(), 1) == mask.end()) return 0;
  const std::vector<uint8_t> region =
      magnify_spots(mask, image.width, image.height, options.magnify);
  fill_region(image, region);
  return static_cast<size_t>(std::count(region.begin(), region.end(), 1));
}

}  // namespace phyxel::render
