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
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    fail(context, "texture file \"" + name + "\" does not exist");
  }
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

void write_png(const std::filesystem::path& file, const RgbaImage& image) {
  if (image.width == 0 || image.height == 0) {
    throw std::runtime_error(file.string() + ": cannot write an empty image");
  }
  // Written to FILE.tmp, then renamed: an interrupted run never leaves half a PNG.
  std::filesystem::path tmp = file;
  tmp += ".tmp";
  const int ok =
      stbi_write_png(tmp.c_str(), static_cast<int>(image.width), static_cast<int>(image.height), 4,
                     image.pixels.data(), static_cast<int>(image.width * 4));
  if (ok == 0) {
    const std::string why = std::strerror(errno);
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw std::runtime_error(file.string() + ": cannot write the PNG file (" + why +
                             "); check the folder and free space");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec)
    throw std::runtime_error(file.string() + ": cannot rename " + tmp.string() + " to it (" +
                             ec.message() + ")");
}

}  // namespace phyxel::render
