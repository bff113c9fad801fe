// Helpers of the render tests: a scene rendered from a phyxel set and a displacement, image
// statistics, and golden-image comparison (tolerance 5/255 per channel on >= 99.9 % of the
// pixels; on failure the actual and difference images go to $PHYXEL_TEST_OUT).
//
// Goldens live in tests/data/render/<name>.png. PHYXEL_UPDATE_GOLDENS=1 rewrites them from
// the current renderer (then look at them before committing).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "engine/solver/neighbours.h"
#include "render/image.h"
#include "render/splat_renderer.h"
#include "tests/vulkan/vulkan_test.h"

namespace phyxel::render::test {

inline bool is_background(const uint8_t* p) {
  return p[0] == kBackground[0] && p[1] == kBackground[1] && p[2] == kBackground[2];
}

// A phyxel set ready to render: neighbours, surfel table, input buffers and renderer.
struct RenderedSet {
  RenderedSet(gpu::Context& ctx, PhyxelSet s, const RgbaImage& texture,
              const std::vector<double>& material_mirror = {})
      : set(std::move(s)),
        neighbours(find_rest_neighbours(set)),
        table(build_surfel_table(set, material_mirror)) {
    inputs = std::make_unique<HostInputs>(ctx, set, neighbours);
    renderer = std::make_unique<SplatRenderer>(ctx, table, texture);
  }
  RgbaImage render(const FrameSetup& setup, const std::vector<Vec3>* u = nullptr) {
    inputs->set_displacement(u ? *u : std::vector<Vec3>(set.size(), Vec3::Zero()));
    return renderer->render(inputs->inputs(), setup);
  }

  PhyxelSet set;
  NeighbourLists neighbours;
  SurfelTable table;
  std::unique_ptr<HostInputs> inputs;
  std::unique_ptr<SplatRenderer> renderer;
};

inline FrameSetup setup_for(const Camera& camera, uint32_t width, uint32_t height,
                            RenderSettings::Mode mode = RenderSettings::Mode::Mono,
                            StereoSettings stereo = {}) {
  RenderSettings r;
  r.width = static_cast<int>(width);
  r.height = static_cast<int>(height);
  r.stereo = stereo;
  return make_frame_setup(camera, r, mode);
}

inline Camera camera_at(const Vec3& position, const Vec3& target, const Vec3& up, double fov = 40) {
  Camera c;
  c.position = position;
  c.target = target;
  c.up = up;
  c.fov_y_deg = fov;
  c.near = 0.01;
  c.far = 2;
  return c;
}

inline std::filesystem::path test_out_dir() {
  const char* out = std::getenv("PHYXEL_TEST_OUT");
  std::filesystem::path dir = out != nullptr ? out : "test-out";
  std::filesystem::create_directories(dir);
  return dir;
}

// Centroid (x, y) of the pixels of the region [x0, x0 + w) for which `pick` holds; count in z.
template <class Pick>
Eigen::Vector3d centroid(const RgbaImage& image, Pick pick, uint32_t x0 = 0, uint32_t w = 0) {
  if (w == 0) w = image.width - x0;
  double sx = 0, sy = 0, n = 0;
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = x0; x < x0 + w; ++x)
      if (pick(image.at(x, y))) {
        sx += x + 0.5 - x0;
        sy += y + 0.5;
        n += 1;
      }
  return n > 0 ? Eigen::Vector3d(sx / n, sy / n, n) : Eigen::Vector3d(-1, -1, 0);
}

inline void expect_matches_golden(const RgbaImage& actual, const std::string& name) {
  const std::filesystem::path golden =
      std::filesystem::path(PHYXEL_SOURCE_DIR) / "tests/data/render" / (name + ".png");
  const char* update = std::getenv("PHYXEL_UPDATE_GOLDENS");
  if (update != nullptr && std::string(update) == "1") {
    write_png(golden, actual);
    std::printf("wrote golden %s\n", golden.c_str());
  }
  RgbaImage expected;
  try {
    expected = load_image(golden, "golden");
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what() << " (generate with PHYXEL_UPDATE_GOLDENS=1)";
    write_png(test_out_dir() / (name + "_actual.png"), actual);
    return;
  }
  ASSERT_EQ(actual.width, expected.width) << name;
  ASSERT_EQ(actual.height, expected.height) << name;
  RgbaImage diff(actual.width, actual.height);
  size_t within = 0;
  int worst = 0;
  for (uint32_t y = 0; y < actual.height; ++y)
    for (uint32_t x = 0; x < actual.width; ++x) {
      int d = 0;
      for (int c = 0; c < 3; ++c)
        d = std::max(d, std::abs(actual.at(x, y)[c] - expected.at(x, y)[c]));
      worst = std::max(worst, d);
      within += d <= 5;
      uint8_t* p = diff.at(x, y);
      p[0] = p[1] = p[2] = static_cast<uint8_t>(std::min(255, d * 8));
      p[3] = 255;
    }
  const double fraction = double(within) / (double(actual.width) * actual.height);
  EXPECT_GE(fraction, 0.999) << name << ": " << (1 - fraction) * 100
                             << " % of the pixels differ by more than 5/255 (worst " << worst
                             << "); see " << (test_out_dir() / (name + "_actual.png")).string();
  if (fraction < 0.999) {
    write_png(test_out_dir() / (name + "_actual.png"), actual);
    write_png(test_out_dir() / (name + "_diff.png"), diff);
  }
}

}  // namespace phyxel::render::test
