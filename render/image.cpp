#include "render/image.h"

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "engine/run/atomic_file.h"
#include "engine/scene/file_kind.h"
#include "engine/scene/scene.h"

namespace phyxel::render {
namespace {

constexpr const char* kAllowedImage = "allowed a PNG or JPEG image of at least 1 x 1 pixels";

[[noreturn]] void fail(const std::string& context, const std::string& problem) {
  throw SceneError(context + ": " + problem + "; " + kAllowedImage);
}

// Value noise on an integer lattice with a hash, smoothly interpolated; in [0, 1].
double hash(int x, int y, uint32_t seed) {
  uint32_t h = static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^
               seed * 0xcb1ab31fu;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return (h & 0xffffffu) / double(0xffffff);
}

double value_noise(double x, double y, uint32_t seed) {
  const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
  const double a = hash(x0, y0, seed), b = hash(x0 + 1, y0, seed);
  const double c = hash(x0, y0 + 1, seed), d = hash(x0 + 1, y0 + 1, seed);
  return (a + (b - a) * sx) + ((c + (d - c) * sx) - (a + (b - a) * sx)) * sy;
}

double fbm(double x, double y, int octaves, uint32_t seed) {
  double sum = 0, amp = 0.5, norm = 0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * value_noise(x, y, seed + o);
    norm += amp;
    x *= 2.03;
    y *= 2.03;
    amp *= 0.5;
  }
  return sum / norm;
}

}  // namespace

RgbaImage load_image(const std::filesystem::path& file, const std::string& context) {
  const std::string name = file.string();
  if (const std::string why = not_a_regular_file(file); !why.empty())
    fail(context, "texture file \"" + name + "\" " + why);
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(context, "cannot open \"" + name + "\" (" + std::strerror(errno) + ")");
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)),
                                   std::istreambuf_iterator<char>());
  if (bytes.empty()) fail(context, "\"" + name + "\" is empty (zero-size image)");
  if (bytes.size() > size_t(1) << 30) fail(context, "\"" + name + "\" is larger than 1 GiB");
  int w = 0, h = 0, channels = 0;
  if (stbi_info_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &channels) &&
      (w <= 0 || h <= 0)) {
    fail(context, "\"" + name + "\" has a zero-size image");
  }
  stbi_uc* data =
      stbi_load_from_memory(bytes.data(), static_cast<int>(bytes.size()), &w, &h, &channels, 4);
  if (data == nullptr) {
    const char* why = stbi_failure_reason();
    fail(context, "cannot decode \"" + name + "\" (" + (why ? why : "unknown error") + ")");
  }
  if (w <= 0 || h <= 0) {
    stbi_image_free(data);
    fail(context, "\"" + name + "\" has a zero-size image");
  }
  RgbaImage image(static_cast<uint32_t>(w), static_cast<uint32_t>(h));
  std::memcpy(image.pixels.data(), data, image.pixels.size());
  stbi_image_free(data);
  return image;
}

RgbaImage procedural_tissue_texture(uint32_t size) {
  RgbaImage image(size, size);
  const double scale = 8.0 / size;  // about 8 noise cells across
  for (uint32_t y = 0; y < size; ++y) {
    for (uint32_t x = 0; x < size; ++x) {
      const double fx = x * scale, fy = y * scale;
      const double mottle = fbm(fx, fy, 5, 11);
      // Vessels: thin bands along level sets of warped noise, two scales.
      const double wx = fx + 1.5 * fbm(fx * 0.7, fy * 0.7, 3, 23);
      const double wy = fy + 1.5 * fbm(fx * 0.7 + 5.2, fy * 0.7 + 1.3, 3, 29);
      const double large = std::abs(fbm(wx * 0.5, wy * 0.5, 4, 37) - 0.5);
      const double small = std::abs(fbm(wx * 1.3, wy * 1.3, 4, 41) - 0.5);
      const double vessel = std::max(std::clamp(1.0 - large / 0.022, 0.0, 1.0),
                                     0.6 * std::clamp(1.0 - small / 0.012, 0.0, 1.0));
      double r = 0.80 + 0.12 * (mottle - 0.5), g = 0.47 + 0.14 * (mottle - 0.5),
             b = 0.44 + 0.10 * (mottle - 0.5);
      r = r * (1 - vessel) + 0.52 * vessel;
      g = g * (1 - vessel) + 0.09 * vessel;
      b = b * (1 - vessel) + 0.12 * vessel;
      uint8_t* p = image.at(x, y);
      p[0] = static_cast<uint8_t>(std::lround(std::clamp(r, 0.0, 1.0) * 255));
      p[1] = static_cast<uint8_t>(std::lround(std::clamp(g, 0.0, 1.0) * 255));
      p[2] = static_cast<uint8_t>(std::lround(std::clamp(b, 0.0, 1.0) * 255));
      p[3] = 255;
    }
  }
  return image;
}

namespace {

double smooth_band(double x, double lo, double hi) {
  const double t = std::clamp((x - lo) / (hi - lo), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// The colour of the operating field at (x, y) in [-1, 1]^2 (y down).
void operating_field_colour(double x, double y, double rgb[3]) {
  const double fx = 6 * (x + 1), fy = 6 * (y + 1);
  const double wobble = 0.06 * (fbm(fx * 0.5, fy * 0.5, 3, 71) - 0.5);
  const double r = std::sqrt(x * x + y * y) + wobble;
  // Tissue: pink parenchyma, sulci (dark folds), vessels and wet glints.
  const double mottle = fbm(fx, fy, 5, 53);
  const double sulcus =
      std::clamp(1 - std::abs(fbm(fx * 0.6, fy * 0.6, 4, 59) - 0.5) / 0.03, 0.0, 1.0);
  const double wx = fx + 1.5 * fbm(fx * 0.7, fy * 0.7, 3, 61);
  const double wy = fy + 1.5 * fbm(fx * 0.7 + 3.1, fy * 0.7 + 7.7, 3, 67);
  const double vessel =
      std::clamp(1 - std::abs(fbm(wx * 0.8, wy * 0.8, 4, 73) - 0.5) / 0.018, 0.0, 1.0);
  const double glint = 0.8 * smooth_band(fbm(fx * 3, fy * 3, 3, 79), 0.77, 0.83);
  double t[3] = {0.78 + 0.14 * (mottle - 0.5), 0.42 + 0.12 * (mottle - 0.5),
                 0.40 + 0.10 * (mottle - 0.5)};
  const double depth = 1 - 0.35 * smooth_band(0.45 - r, 0.0, 0.45);  // the cavity is darker
  const double vein[3] = {0.45, 0.06, 0.10}, fold[3] = {0.35, 0.10, 0.10};
  for (int c = 0; c < 3; ++c) {
    t[c] = t[c] * (1 - vessel) + vein[c] * vessel;
    t[c] = t[c] * (1 - 0.7 * sulcus) + fold[c] * 0.7 * sulcus;
    t[c] = t[c] * depth * (1 - glint) + 0.95 * glint;
  }
  // The rim of the opening: blood and shadow. Drapes beyond: green, folds shaded.
  const double fold_wave = std::sin(9 * std::atan2(y, x) + 6 * fbm(fx * 0.3, fy * 0.3, 3, 83));
  const double drape_light = 0.75 + 0.25 * fold_wave * (0.6 + 0.4 * fbm(fx, fy, 3, 89));
  const double drape[3] = {0.17 * drape_light, 0.42 * drape_light, 0.38 * drape_light};
  const double rim[3] = {0.30, 0.04, 0.05};
  const double to_rim = smooth_band(r, 0.66, 0.72), to_drape = smooth_band(r, 0.76, 0.8);
  for (int c = 0; c < 3; ++c) {
    rgb[c] = t[c] * (1 - to_rim) + rim[c] * to_rim;
    rgb[c] = rgb[c] * (1 - to_drape) + drape[c] * to_drape;
  }
  // Three steel retractor blades across the rim, each with a bright glint along its middle.
  const double angles[3] = {-2.2, 0.4, 2.5};
  for (double a : angles) {
    const double dx = std::cos(a), dy = std::sin(a);
    const double along = x * dx + y * dy, across = std::abs(-x * dy + y * dx);
    if (along < 0.6 || along > 1.4 || across > 0.07) continue;
    const double shade = 0.45 + 0.2 * along + 0.5 * std::pow(1 - across / 0.07, 8.0);
    const double steel[3] = {0.62, 0.64, 0.68};
    for (int c = 0; c < 3; ++c) rgb[c] = std::min(1.0, steel[c] * shade);
  }
}

}  // namespace

RgbaImage procedural_operating_field(uint32_t size) {
  RgbaImage image(size, size);
  for (uint32_t py = 0; py < size; ++py) {
    for (uint32_t px = 0; px < size; ++px) {
      double rgb[3];
      operating_field_colour((2.0 * px + 1) / size - 1, (2.0 * py + 1) / size - 1, rgb);
      uint8_t* p = image.at(px, py);
      for (int c = 0; c < 3; ++c)
        p[c] = static_cast<uint8_t>(std::lround(std::clamp(rgb[c], 0.0, 1.0) * 255));
      p[3] = 255;
    }
  }
  return image;
}

void write_png(const std::filesystem::path& file, const RgbaImage& image) {
  if (image.width == 0 || image.height == 0) {
    throw std::runtime_error(file.string() + ": cannot write an empty image");
  }
  std::string png;
  const int ok = stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
      },
      &png, static_cast<int>(image.width), static_cast<int>(image.height), 4, image.pixels.data(),
      static_cast<int>(image.width * 4));
  if (ok == 0) throw std::runtime_error(file.string() + ": cannot encode the PNG image");
  write_file_atomically(file, png);
}

}  // namespace phyxel::render
