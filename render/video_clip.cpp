#include "render/video_clip.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/video_writer.h"

namespace phyxel::render {
namespace {

constexpr double kTau = 2 * std::numbers::pi;

uint8_t to_byte(double v) {
  return static_cast<uint8_t>(std::clamp(std::lround(v * 255.0), 0L, 255L));
}

// A vessel: the curve y = y0 + a sin(f x + p) + b sin(g x + q) across the field (x and y
// exchanged when `vertical`), in units of the frame's height.
struct Vessel {
  double y0, a, f, p, b, g, q, width;
  bool vertical;
};

constexpr Vessel kVessels[] = {
    {0.30, 0.06, 7.0, 0.3, 0.02, 19.0, 1.1, 0.020, false},
    {0.62, 0.08, 5.0, 2.0, 0.03, 13.0, 0.4, 0.028, false},
    {0.85, 0.04, 9.0, 4.1, 0.02, 23.0, 2.7, 0.014, false},
    {0.12, 0.05, 6.0, 1.7, 0.01, 29.0, 0.9, 0.010, false},
    {0.22, 0.05, 8.0, 0.9, 0.02, 17.0, 2.1, 0.016, true},
    {0.50, 0.07, 6.0, 3.0, 0.02, 21.0, 0.2, 0.022, true},
    {0.78, 0.04, 10.0, 1.4, 0.01, 27.0, 1.9, 0.012, true},
};

}  // namespace

RgbaImage pulsing_tissue_frame(const VideoClipOptions& o, int index) {
  RgbaImage image(o.width, o.height);
  const double t = index / o.fps;
  const double phase = kTau * t / o.pulse_s;
  // A heartbeat: a sharp systole and a slow relaxation, 0 ... 1.
  const double beat = std::pow(0.5 + 0.5 * std::sin(phase), 3.0);
  const double swell = 1.0 - 0.025 * beat;  // the field bulges towards the camera
  // Two glints (specular spots), moving a little with the swelling.
  const double gx[2] = {0.36 + 0.01 * beat, 0.70 - 0.012 * beat};
  const double gy[2] = {0.44 - 0.01 * beat, 0.24 + 0.008 * beat};
  const double gr[2] = {0.035, 0.022};
  for (uint32_t py = 0; py < o.height; ++py) {
    for (uint32_t px = 0; px < o.width; ++px) {
      const double u0 = (px + 0.5) / o.height, v0 = (py + 0.5) / o.height;
      const double cx = 0.5 * o.width / o.height;
      const double u = cx + (u0 - cx) * swell, v = 0.5 + (v0 - 0.5) * swell;
      // Parenchyma: pink with soft mottling.
      const double mottle = 0.5 + 0.25 * std::sin(23 * u + 3 * std::sin(11 * v)) +
                            0.25 * std::sin(31 * v + 2 * std::sin(17 * u + 1.3));
      double r = 0.80 + 0.08 * mottle, g = 0.42 + 0.10 * mottle, b = 0.42 + 0.08 * mottle;
      for (const Vessel& k : kVessels) {
        const double along = k.vertical ? v : u, across = k.vertical ? u : v;
        const double y =
            k.y0 + k.a * std::sin(k.f * along + k.p) + k.b * std::sin(k.g * along + k.q);
        const double width = k.width * (1 + 0.45 * beat);
        const double d = std::abs(across - y) / width;
        if (d < 2) {
          const double core = std::exp(-d * d * 2.5);
          const double dark = 0.55 + 0.2 * beat;  // fuller, darker at systole
          r = r * (1 - core) + (0.55 - 0.15 * dark) * core;
          g = g * (1 - core * dark) + 0.05 * core * dark;
          b = b * (1 - core * dark) + 0.10 * core * dark;
        }
      }
      if (o.glints) {
        for (int s = 0; s < 2; ++s) {
          const double d = std::hypot(u - gx[s], (v - gy[s]) * 1.6) / gr[s];
          const double w = std::clamp((1.15 - d) / 0.3, 0.0, 1.0);  // a soft rim
          r += (0.99 - r) * w;
          g += (0.97 - g) * w;
          b += (0.95 - b) * w;
        }
      }
      uint8_t* p = image.at(px, py);
      p[0] = to_byte(r);
      p[1] = to_byte(g);
      p[2] = to_byte(b);
      p[3] = 255;
    }
  }
  return image;
}

void write_pulsing_tissue_clip(const std::filesystem::path& file, const VideoClipOptions& o) {
  VideoWriter video(file, o.width, o.height, o.fps, VideoEncoding::H264Lossless);
  for (int k = 0; k < o.frames; ++k) video.add(pulsing_tissue_frame(o, k), k);
  video.finish();
}

}  // namespace phyxel::render
