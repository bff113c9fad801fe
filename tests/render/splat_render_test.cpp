// The splat renderer on lavapipe with validation: closed surfaces without holes, the texture
// following the tissue, stereo on the GPU, anaglyph and swap, and golden images.
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "render/sample_shapes.h"
#include "render/texture_map.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

using test::RenderedSet;

class SplatRender : public gpu::VulkanTest {};

// Samples a sphere scene with the engine's sampler (the production path of surface phyxels).
PhyxelSet sampled_sphere(double radius, double spacing) {
  const std::string json = R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"name": "s",
      "shape": {"type": "sphere", "center": [0, 0, 0], "radius": )" +
                           std::to_string(radius) + R"(}, "spacing": )" + std::to_string(spacing) +
                           R"(,
      "material": {"young": 1000, "poisson": 0.3, "density": 1000}}]})";
  return sample_scene(parse_scene(json, "sphere.json"));
}

// Holes seen from `distance` along six directions (oblique to the lattice, where its
// staircase shows most): the surfels of the far side are
// left out (splat radius 0 where x.d < -2 spacings), so that a ray through a gap in the near
// side shows the background instead of the far side. Counts background pixels inside the
// projected disc of the ball of radius `inner` (which the closed surface encloses), shrunk by
// one pixel.
int holes_in_six_views(gpu::Context& ctx, const PhyxelSet& set, double inner, double spacing,
                       std::string* report) {
  const double distance = 0.12, fov = 30;
  const uint32_t size = 128;
  const std::array<Vec3, 6> dirs = {Vec3(1, 0.3, 0.5),    Vec3(-0.4, 1, 0.2),  Vec3(0.2, -0.5, 1),
                                    Vec3(-1, -0.3, -0.5), Vec3(0.4, -1, -0.2), Vec3(-0.2, 0.5, -1)};
  int holes = 0;
  for (const Vec3& dir : dirs) {
    const Vec3 d = dir.normalized();
    PhyxelSet near_side = set;
    for (size_t i = 0; i < set.size(); ++i)
      if (set.rest[i].dot(d) < -2 * spacing) near_side.splat_radius[i] = 0;
    RenderedSet s(ctx, std::move(near_side), procedural_tissue_texture(64));
    const Vec3 up = std::abs(d.z()) > 0.5 ? Vec3::UnitY() : Vec3::UnitZ();
    const Camera cam = test::camera_at(distance * d, Vec3::Zero(), up, fov);
    const RgbaImage image = s.render(test::setup_for(cam, size, size));
    const double limit =
        std::tan(std::asin(inner / distance)) / std::tan(0.5 * fov * M_PI / 180) * size / 2 - 1.0;
    int inside = 0, here = 0;
    for (uint32_t y = 0; y < size; ++y)
      for (uint32_t x = 0; x < size; ++x) {
        if (std::hypot(x + 0.5 - size / 2.0, y + 0.5 - size / 2.0) > limit) continue;
        ++inside;
        if (!test::is_background(image.at(x, y))) continue;
        if (++here <= 4 && report)
          *report += " (" + std::to_string(x) + ", " + std::to_string(y) + ")";
      }
    EXPECT_GT(inside, 2000);
    EXPECT_TRUE(test::is_background(image.at(2, 2))) << "nothing far outside the sphere";
    if (here > 0 && report) {
      *report += " from " + std::to_string(d.x()) + "," + std::to_string(d.y()) + "," +
                 std::to_string(d.z()) + ";";
      write_png(test::test_out_dir() / "sphere_holes.png", image);
    }
    holes += here;
  }
  return holes;
}

TEST_F(SplatRender, ClosedSphereCoversItsSilhouetteFromSixDirections) {
  const double radius = 0.02, spacing = 0.002;
  PhyxelSet set = sampled_sphere(radius, spacing);
  // The lattice's surface phyxels lie between about R - s and R: the ball they enclose has
  // the radius of the nearest one.
  double inner = radius;
  for (size_t i = 0; i < set.size(); ++i)
    if (set.flags[i] & kSurface) inner = std::min(inner, set.rest[i].norm());
  EXPECT_GT(inner, radius - spacing);
  std::string report;
  EXPECT_EQ(holes_in_six_views(ctx(), set, inner, spacing, &report), 0)
      << "background at" << report;

  // The check finds holes where there are some: splats half as large leave gaps.
  for (double& r : set.splat_radius) r *= 0.5;
  EXPECT_GT(holes_in_six_views(ctx(), set, inner, spacing, nullptr), 100);
}

TEST_F(SplatRender, MarkedTexelMovesWithItsPhyxel) {
  PhyxelSet box = lattice_box(Vec3(-0.02, -0.02, 0), Vec3(0.02, 0.02, 0.02), 0.004);
  // The top-face phyxel near (0.008, 0.004, 0.02) gets a red mark in a grey texture.
  size_t marked = 0;
  double best = 1e9;
  for (size_t i = 0; i < box.size(); ++i) {
    const double d = (box.rest[i] - Vec3(0.008, 0.004, 0.02)).norm();
    if (d < best) best = d, marked = i;
  }
  const SurfelTable table = build_surfel_table(box);
  Eigen::Vector2d st(-1, -1);
  for (const layout::SurfelStatic& v : table.surfels)
    if (v.index == marked) st = {v.ds_dx.w, v.dt_dx.w};
  ASSERT_GE(st.x(), 0.0);
  RgbaImage texture(256, 256);
  for (uint32_t y = 0; y < 256; ++y)
    for (uint32_t x = 0; x < 256; ++x) {
      uint8_t* p = texture.at(x, y);
      const bool mark =
          std::abs(x + 0.5 - st.x() * 256) < 3 && std::abs(y + 0.5 - st.y() * 256) < 3;
      p[0] = mark ? 255 : 150;
      p[1] = p[2] = mark ? 0 : 150;
      p[3] = 255;
    }
  RenderedSet s(ctx(), box, texture);
  const Camera cam = test::camera_at(Vec3(0, -0.05, 0.12), Vec3(0, 0, 0.01), Vec3::UnitZ(), 40);
  const FrameSetup setup = test::setup_for(cam, 160, 160);
  auto red = [](const uint8_t* p) { return p[0] > p[1] + 60; };

  // At rest, and under an affine deformation (shear + stretch + translation, which the MLS
  // gradient reproduces exactly).
  std::vector<Vec3> u(s.set.size());
  for (size_t i = 0; i < u.size(); ++i) {
    const Vec3& x = s.set.rest[i];
    u[i] = Vec3(0.4 * x.z() + 0.15 * x.x() - 0.004, 0.2 * x.x() + 0.003, 0.1 * x.z());
  }
  const std::vector<Vec3>* const fields[] = {nullptr, &u};
  for (const std::vector<Vec3>* field : fields) {
    const RgbaImage image = s.render(setup, field);
    const Eigen::Vector3d c = test::centroid(image, red);
    const Vec3 x = s.set.rest[marked] + (field ? (*field)[marked] : Vec3::Zero());
    const Eigen::Vector3d expected = project_to_pixel(setup.eyes[0], x, 160, 160);
    EXPECT_GT(c.z(), 3) << "the mark is visible";
    EXPECT_NEAR(c.x(), expected.x(), 1.0) << (field ? "deformed" : "rest");
    EXPECT_NEAR(c.y(), expected.y(), 1.0) << (field ? "deformed" : "rest");
  }
  const Eigen::Vector3d moved =
      project_to_pixel(setup.eyes[0], s.set.rest[marked] + u[marked], 160, 160) -
      project_to_pixel(setup.eyes[0], s.set.rest[marked], 160, 160);
  EXPECT_GT(moved.head<2>().norm(), 5.0) << "the deformation moves the mark visibly";
}

TEST_F(SplatRender, StereoOnTheGpuZeroParallaxAtTheFocalDistance) {
  // Two small spheres: one at the focal distance, one nearer. Their centroids in the two
  // halves of a side-by-side frame: equal for the first, crossed parallax for the second.
  const double spacing = 0.0015;
  const Camera cam = test::camera_at(Vec3(0, -0.3, 0), Vec3::Zero(), Vec3::UnitZ(), 30);
  StereoSettings st;
  st.ipd = 0.03;
  st.focal_distance = 0.3;
  const FrameSetup setup = test::setup_for(cam, 128, 96, RenderSettings::Mode::Stereo, st);
  for (const double y : {0.0, -0.1}) {
    RenderedSet s(ctx(), lattice_sphere(Vec3(0.01, y, 0.005), 0.01, spacing, 3 * spacing),
                  procedural_tissue_texture(64));
    const RgbaImage image = s.render(setup);
    ASSERT_EQ(image.width, 256u);
    auto covered = [](const uint8_t* p) { return !test::is_background(p); };
    const Eigen::Vector3d left = test::centroid(image, covered, 0, 128);
    const Eigen::Vector3d right = test::centroid(image, covered, 128, 128);
    EXPECT_GT(left.z(), 50);
    EXPECT_NEAR(left.y(), right.y(), 0.25) << "no vertical parallax";
    const Vec3 centre(0.01, y, 0.005);
    const double expected = project_to_pixel(setup.eyes[1], centre, 128, 96).x() -
                            project_to_pixel(setup.eyes[0], centre, 128, 96).x();
    EXPECT_NEAR(right.x() - left.x(), expected, 0.35) << "at y = " << y;
    if (y == 0.0) {
      EXPECT_NEAR(expected, 0.0, 1e-9);
    } else {
      EXPECT_LT(right.x() - left.x(), -2.0);
    }
  }
}

TEST_F(SplatRender, AnaglyphAndSwappedEyesComeFromTheSideBySidePair) {
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006),
                procedural_tissue_texture(64));
  const Camera cam = test::camera_at(Vec3(0.05, -0.15, 0.05), Vec3::Zero(), Vec3::UnitZ(), 35);
  StereoSettings st;
  st.ipd = 0.02;
  const RgbaImage pair = s.render(test::setup_for(cam, 80, 64, RenderSettings::Mode::Stereo, st));
  st.swap_eyes = true;
  const RgbaImage swapped =
      s.render(test::setup_for(cam, 80, 64, RenderSettings::Mode::Stereo, st));
  st.swap_eyes = false;
  st.layout = StereoSettings::Layout::Anaglyph;
  const RgbaImage anaglyph =
      s.render(test::setup_for(cam, 80, 64, RenderSettings::Mode::Stereo, st));
  ASSERT_EQ(anaglyph.width, 80u);
  int differ = 0;
  for (uint32_t y = 0; y < 64; ++y)
    for (uint32_t x = 0; x < 80; ++x) {
      const uint8_t *l = pair.at(x, y), *r = pair.at(x + 80, y), *a = anaglyph.at(x, y);
      ASSERT_EQ(a[0], l[0]);
      ASSERT_EQ(a[1], r[1]);
      ASSERT_EQ(a[2], r[2]);
      ASSERT_EQ(a[3], 255);
      for (int c = 0; c < 4; ++c) {
        ASSERT_EQ(swapped.at(x, y)[c], r[c]);
        ASSERT_EQ(swapped.at(x + 80, y)[c], l[c]);
      }
      differ += l[0] != r[0];
    }
  EXPECT_GT(differ, 50) << "the eyes see different images";
}

TEST_F(SplatRender, CoplanarNeighboursRenderWhereMovedWithTheRestNormal) {
  // One layer of phyxels: every moment matrix is singular (regularised, as the solver's). The
  // sheet, translated, still renders where it was moved, with its rest normal.
  RenderedSet s(ctx(), lattice_box(Vec3(-0.02, -0.02, 0), Vec3(0.02, 0.02, 0), 0.004),
                procedural_tissue_texture(64));
  const Camera cam = test::camera_at(Vec3(0, 0, 0.1), Vec3::Zero(), Vec3::UnitY(), 40);
  std::vector<Vec3> u(s.set.size(), Vec3(0.01, 0, 0));
  const RgbaImage image = s.render(test::setup_for(cam, 96, 96), &u);
  const Eigen::Vector3d c =
      test::centroid(image, [](const uint8_t* p) { return !test::is_background(p); });
  EXPECT_NEAR(c.x(), project_to_pixel(mono_eye(cam, 1), Vec3(0.01, 0, 0), 96, 96).x(), 1.0);
  EXPECT_GT(c.z(), 1500);
}

// Goldens: 192 x 192 (per eye), lavapipe.
TEST_F(SplatRender, GoldenSphere) {
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.024, 0.002, 0.006),
                procedural_tissue_texture(256));
  const Camera cam = test::camera_at(Vec3(0.03, -0.09, 0.05), Vec3::Zero(), Vec3::UnitZ(), 35);
  test::expect_matches_golden(s.render(test::setup_for(cam, 192, 192)), "sphere");
}

TEST_F(SplatRender, GoldenDeformedTexturedBlock) {
  RenderedSet s(ctx(), lattice_box(Vec3(-0.03, -0.02, 0), Vec3(0.03, 0.02, 0.02), 0.0025),
                procedural_tissue_texture(256));
  std::vector<Vec3> u(s.set.size());
  for (size_t i = 0; i < u.size(); ++i) {
    const Vec3& x = s.set.rest[i];
    // Bending about y plus a dent: smooth, non-affine.
    const double bend = 6.0 * x.x() * x.x();
    const double dent = -0.006 * std::exp(-(x.x() * x.x() + x.y() * x.y()) / 1e-4) * x.z() / 0.02;
    u[i] = Vec3(-12.0 * x.x() * (x.z() - 0.01), 0, bend + dent);
  }
  const Camera cam = test::camera_at(Vec3(0.04, -0.08, 0.08), Vec3(0, 0, 0.012), Vec3::UnitZ(), 40);
  test::expect_matches_golden(s.render(test::setup_for(cam, 192, 192), &u), "deformed_block");
}

TEST_F(SplatRender, GoldenStereoPair) {
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.02, 0.002, 0.006),
                procedural_tissue_texture(256));
  const Camera cam = test::camera_at(Vec3(0, -0.1, 0.04), Vec3::Zero(), Vec3::UnitZ(), 35);
  StereoSettings st;
  st.ipd = 0.02;
  st.focal_distance = 0.1;
  test::expect_matches_golden(
      s.render(test::setup_for(cam, 160, 160, RenderSettings::Mode::Stereo, st)), "stereo_pair");
}

}  // namespace
}  // namespace phyxel::render
