// Cube mirror environment mapping (render/environment_map.h, the paper's eqs 33-34): the
// mapping against the printed formulas, the background cube and a mirror sphere on lavapipe
// (known colours where they must be, and goldens), the scene keys and their errors.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "render/environment_map.h"
#include "render/sample_shapes.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

// The paper's eqs 33 (u) and 34 (v) for a point Q = (x, y, z) on a side face of the cube of
// side D, as printed; the texture plane's border is at (D / 2) sqrt(K + 4 / K).
Eigen::Vector2d paper_side_uv(const Vec3& q, double k, double d) {
  const double s_x = std::sqrt(k * d * d / 4 + d * d / (2 * k) - d / k * q.z());
  const double s_y = std::sqrt(k + 2 / k - 4 / (k * d) * q.z());
  const bool x_face = std::abs(std::abs(q.x()) - d / 2) < 1e-12;
  const double u = x_face ? q.x() / std::abs(q.x()) * s_x : q.x() * s_y;
  const double v = x_face ? q.y() * s_y : q.y() / std::abs(q.y()) * s_x;
  return {u, v};
}

TEST(EnvironmentMap, SideFacesFollowEquations33And34) {
  const double k = 1.7, d = 0.6;  // any cube: only directions matter
  const double border = d / 2 * std::sqrt(k + 4 / k);
  const Vec3 points[] = {Vec3(d / 2, 0.1, 0.05), Vec3(-d / 2, -0.2, -0.25), Vec3(0.12, d / 2, 0.2),
                         Vec3(-0.07, -d / 2, -0.29)};
  for (const Vec3& q : points) {
    const Eigen::Vector2d uv = paper_side_uv(q, k, d);
    const Eigen::Vector2d expected(0.5 + 0.5 * uv.x() / border, 0.5 + 0.5 * uv.y() / border);
    const Eigen::Vector2d st = environment_st(q, k);
    EXPECT_NEAR(st.x(), expected.x(), 1e-12) << q.transpose();
    EXPECT_NEAR(st.y(), expected.y(), 1e-12) << q.transpose();
    EXPECT_NEAR(environment_st(3.5 * q, k).x(), st.x(), 1e-12) << "depends on direction only";
  }
}

TEST(EnvironmentMap, TopFaceIsTheMiddleSquareAndTheSidesTheRing) {
  const double k = 1.0;
  const double inner = 0.5 * std::sqrt(k) / std::sqrt(k + 4 / k);  // half side of the square
  EXPECT_NEAR(environment_st(Vec3(0, 0, 1), k).x(), 0.5, 1e-12);
  // The top face's corner is the square's corner; the sides' top edge meets it there.
  const Eigen::Vector2d corner = environment_st(Vec3(1, 1, 1), k);
  EXPECT_NEAR(corner.x(), 0.5 + inner, 1e-12);
  EXPECT_NEAR(corner.y(), 0.5 + inner, 1e-12);
  const Eigen::Vector2d top_side = environment_st(Vec3(1, 0.3, 1 - 1e-9), k);
  const Eigen::Vector2d top_face = environment_st(Vec3(1 - 1e-9, 0.3, 1), k);
  EXPECT_NEAR(top_side.x(), top_face.x(), 1e-8);
  EXPECT_NEAR(top_side.y(), top_face.y(), 1e-8);
  // The sides' bottom edge is the image's border; x right, y down.
  EXPECT_NEAR(environment_st(Vec3(1, 0, -1 + 1e-12), k).x(), 1.0, 1e-9);
  EXPECT_NEAR(environment_st(Vec3(0, -1, -1 + 1e-12), k).y(), 0.0, 1e-9);
  // The bottom face (behind the camera) shows the middle square again.
  EXPECT_NEAR(environment_st(Vec3(0.5, 0, -1), k).x(), environment_st(Vec3(0.5, 0, 1), k).x(),
              1e-12);
}

TEST(EnvironmentMap, BasisLooksAlongTheCameraWithYDown) {
  Camera c;
  c.position = Vec3(0, -1, 0.5);
  c.target = Vec3(0, 0, 0);
  const Eigen::Matrix3d m = environment_basis(c);
  EXPECT_NEAR((m * c.forward() - Vec3(0, 0, 1)).norm(), 0, 1e-12);
  EXPECT_NEAR((m * c.true_up() - Vec3(0, -1, 0)).norm(), 0, 1e-12);
  EXPECT_NEAR((m * m.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
}

// A known cube map, 64 x 64, K = 1: the middle square red; the ring green on the left, blue
// on the right, yellow at the top, cyan at the bottom (by the larger of |u|, |v|).
constexpr uint8_t kRed[3] = {255, 0, 0}, kGreen[3] = {0, 255, 0}, kBlue[3] = {0, 0, 255},
                  kYellow[3] = {255, 255, 0}, kCyan[3] = {0, 255, 255};
RgbaImage sector_environment() {
  const uint32_t n = 64;
  const double inner = 1 / std::sqrt(5.0);  // sqrt(K) / sqrt(K + 4 / K), K = 1
  RgbaImage image(n, n);
  for (uint32_t y = 0; y < n; ++y)
    for (uint32_t x = 0; x < n; ++x) {
      const double u = (2.0 * x + 1) / n - 1, v = (2.0 * y + 1) / n - 1;
      const uint8_t* c = std::max(std::abs(u), std::abs(v)) < inner ? kRed
                         : std::abs(u) >= std::abs(v)               ? (u < 0 ? kGreen : kBlue)
                         : v < 0                                    ? kYellow
                                                                    : kCyan;
      uint8_t* p = image.at(x, y);
      p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
    }
  return image;
}

::testing::AssertionResult near_colour(const RgbaImage& image, uint32_t x, uint32_t y,
                                       const uint8_t* want, int tolerance = 40) {
  const uint8_t* p = image.at(x, y);
  for (int c = 0; c < 3; ++c)
    if (std::abs(int(p[c]) - int(want[c])) > tolerance)
      return ::testing::AssertionFailure()
             << "pixel (" << x << ", " << y << ") is " << int(p[0]) << "," << int(p[1]) << ","
             << int(p[2]) << ", expected about " << int(want[0]) << "," << int(want[1]) << ","
             << int(want[2]);
  return ::testing::AssertionSuccess();
}

class EnvironmentRender : public gpu::VulkanTest {};

TEST_F(EnvironmentRender, BackgroundIsTheCube) {
  // A small sphere far below the view; a 120 degree field of view sees the top face in the
  // middle and the four sides at the edges.
  test::RenderedSet s(ctx(), lattice_sphere(Vec3(0, 0, -0.5), 0.004, 0.002),
                      procedural_tissue_texture(64));
  const Camera cam = test::camera_at(Vec3(0, -0.1, 0), Vec3::Zero(), Vec3::UnitZ(), 120);
  s.renderer->set_environment(sector_environment(), environment_basis(cam), 1.0);
  const RgbaImage image = s.render(test::setup_for(cam, 96, 96));
  EXPECT_TRUE(near_colour(image, 48, 48, kRed, 2));
  EXPECT_TRUE(near_colour(image, 2, 48, kGreen, 2));
  EXPECT_TRUE(near_colour(image, 93, 48, kBlue, 2));
  EXPECT_TRUE(near_colour(image, 48, 2, kYellow, 2));
  EXPECT_TRUE(near_colour(image, 48, 93, kCyan, 2));
  test::expect_matches_golden(image, "environment_background");
}

TEST_F(EnvironmentRender, MirrorSphereReflectsTheCube) {
  // The sphere's material has mirror 1: it shows the cube as a mirror ball does.
  test::RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.02, 0.002, 0.006),
                      procedural_tissue_texture(64), {1.0});
  const Camera cam = test::camera_at(Vec3(0, -0.1, 0), Vec3::Zero(), Vec3::UnitZ(), 35);
  s.renderer->set_environment(sector_environment(), environment_basis(cam), 1.0);
  const uint32_t n = 128;
  const RgbaImage image = s.render(test::setup_for(cam, n, n));
  // The centre reflects the view back: the bottom face, the middle square again. Just inside
  // the silhouette the reflection grazes on forward: the top face. Halfway out the sides.
  const double r = project_to_pixel(mono_eye(cam, 1), Vec3(0.02, 0, 0), n, n).x() - n / 2.0;
  const auto at = [&](double fx, double fy) {
    return std::pair<uint32_t, uint32_t>(uint32_t(n / 2.0 + fx * r), uint32_t(n / 2.0 + fy * r));
  };
  const std::pair<double, double> probes[] = {{0, 0},     {0.97, 0},  {0.55, 0},
                                              {-0.55, 0}, {0, -0.55}, {0, 0.55}};
  const uint8_t* expected[] = {kRed, kRed, kBlue, kGreen, kYellow, kCyan};
  for (size_t i = 0; i < 6; ++i) {
    const auto [x, y] = at(probes[i].first, probes[i].second);
    EXPECT_TRUE(near_colour(image, x, y, expected[i])) << "probe " << i;
  }
  EXPECT_TRUE(near_colour(image, 2, 2, kRed, 2)) << "the background: the top face";
  test::expect_matches_golden(image, "environment_mirror_sphere");
}

TEST(EnvironmentScene, KeysAndErrors) {
  const std::filesystem::path dir = test::test_out_dir() / "environment_scene";
  std::filesystem::create_directories(dir);
  write_png(dir / "square.png", RgbaImage(8, 8));
  write_png(dir / "wide.png", RgbaImage(8, 4));
  const std::string head = R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"name": "b",
      "shape": {"type": "box", "min": [0, 0, 0], "max": [0.01, 0.01, 0.01]}, "spacing": 0.0025,
      "material": {"young": 1000, "poisson": 0.3, "density": 1000}, "mirror": 0.25,
      "inclusions": [{"shape": {"type": "sphere", "center": [0.005, 0.005, 0.005],
      "radius": 0.003}, "material": {"young": 3000, "poisson": 0.3, "density": 1000},
      "mirror": 1}]}], "render": )";
  const Scene scene = parse_scene(
      head + R"({"environment": {"image": "square.png", "area_ratio": 2}, "video": "a.mp4"}})",
      dir / "s.json");
  EXPECT_EQ(scene.render.environment, dir / "square.png");
  EXPECT_EQ(scene.render.environment_area_ratio, 2);
  EXPECT_EQ(scene.render.video, "a.mp4");
  EXPECT_EQ(material_mirrors(scene), (std::vector<double>{0.25, 1.0}));
  const PhyxelSet set = sample_scene(scene);
  const SurfelTable table = build_surfel_table(set, material_mirrors(scene));
  int mirror_levels[256] = {};
  for (const layout::SurfelStatic& sf : table.surfels)
    ++mirror_levels[(sf.flags >> layout::kSurfelMirrorShift) & layout::kMirrorLevels];
  EXPECT_GT(mirror_levels[64], 0) << "the box's surface: 0.25 x 255";
  EXPECT_EQ(mirror_levels[0], 0);

  const Scene wide = parse_scene(head + R"({"environment": "wide.png"}})", dir / "w.json");
  try {
    load_environment(wide.render.environment, "w.json: render.environment");
    ADD_FAILURE() << "a 8 x 4 environment image was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("w.json: render.environment: the environment image"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("is 8 x 4 pixels; allowed a square image"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(parse_scene(head + R"({"environment": "missing.png"}})", dir / "m.json"),
               SceneError);
  try {
    parse_scene(head + R"({"environment": {"image": "square.png", "area_ratio": 0}}})",
                dir / "k.json");
    ADD_FAILURE() << "area_ratio 0 was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("render.environment.area_ratio"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace phyxel::render
