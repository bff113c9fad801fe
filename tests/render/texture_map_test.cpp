// Point-based texture mapping (the paper's eqs 1-7) against hand-computed values, the dome
// fit, and texture files (stb_image) with their error messages.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "render/image.h"
#include "render/sample_shapes.h"
#include "render/surfels.h"
#include "render/texture_map.h"
#include "tests/render/render_test_util.h"
#include "tests/support/support.h"

namespace phyxel::render {
namespace {

TEST(TextureMap, HemisphereToDiscEqs2And3) {
  // Eq 7 (phi = pi/2): u = x / sqrt(1 + z), v = y / sqrt(1 + z).
  EXPECT_NEAR(hemisphere_uv(Vec3(0, 0, 1)).norm(), 0.0, 1e-15);  // pole -> centre
  EXPECT_NEAR(hemisphere_uv(Vec3(1, 0, 0)).x(), 1.0, 1e-15);     // equator -> rim
  EXPECT_NEAR(hemisphere_uv(Vec3(0, -1, 0)).y(), -1.0, 1e-15);
  EXPECT_NEAR(hemisphere_uv(Vec3(0.6, 0, 0.8)).x(), 0.447213595499958, 1e-12);  // 0.6/sqrt(1.8)
  EXPECT_NEAR(hemisphere_uv(Vec3(0, -0.6, 0.8)).y(), -0.447213595499958, 1e-12);
  // Eqs 2-3 with phi = pi/3: another 1/sqrt(1 - cos phi) = sqrt(2).
  EXPECT_NEAR(hemisphere_uv(Vec3(0.6, 0, 0.8), std::numbers::pi / 3).x(), 0.632455532033676, 1e-12);
  // Equal area ratio (eq 1): the cap of polar angle 60 deg (area pi, half the hemisphere)
  // maps to the disc of radius sqrt(1/2) (half the disc's area).
  const double s60 = std::sin(std::numbers::pi / 3);
  EXPECT_NEAR(hemisphere_uv(Vec3(s60, 0, 0.5)).x(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(hemisphere_uv(Vec3(0, s60, 0.5)).y(), std::sqrt(0.5), 1e-12);
}

TEST(TextureMap, RayFromPThroughTheSplatToTheSphereEqs4To6) {
  // P at the centre (the paper's simplification): X = k Q with k = R / |Q|.
  // Q = (0.3, 0.4, 1.2), |Q| = 1.3, R = 2: k = 2 / 1.3, X / R = Q / 1.3.
  const Vec3 x = sphere_point(Vec3(0.3, 0.4, 1.2), 2.0, 0.0);
  EXPECT_NEAR(x.x(), 0.230769230769231, 1e-12);
  EXPECT_NEAR(x.y(), 0.307692307692308, 1e-12);
  EXPECT_NEAR(x.z(), 0.923076923076923, 1e-12);
  const Eigen::Vector2d uv = hemisphere_uv(x);
  EXPECT_NEAR(uv.x(), 0.166410058867569, 1e-12);
  EXPECT_NEAR(uv.y(), 0.221880078490092, 1e-12);
  // P = (0, 0, -1/2) inside the unit sphere, Q = (1/2, 0, 0): eq 5 gives
  // k^2 - k - 3/2 = 0, k = (1 + sqrt 7) / 2 = 1.82287565553230, X = (k/2, 0, k/2 - 1/2).
  const Vec3 y = sphere_point(Vec3(0.5, 0, 0), 1.0, -0.5);
  EXPECT_NEAR(y.x(), 0.911437827766148, 1e-12);
  EXPECT_NEAR(y.y(), 0.0, 1e-15);
  EXPECT_NEAR(y.z(), 0.411437827766148, 1e-12);
  EXPECT_NEAR(y.norm(), 1.0, 1e-12);
  EXPECT_NEAR(hemisphere_uv(y).x(), 0.767178057711411, 1e-12);
  // Off-axis splat, R = 1/2, P = (0, 0, -0.2): k = 1.28708698201915.
  const Vec3 z = sphere_point(Vec3(0.2, -0.3, 0.1), 0.5, -0.2);
  EXPECT_NEAR(z.x(), 0.514834792807662, 1e-12);
  EXPECT_NEAR(z.y(), -0.772252189211493, 1e-12);
  EXPECT_NEAR(z.z(), 0.372252189211493, 1e-12);
  EXPECT_NEAR(hemisphere_uv(z).x(), 0.439491948220112, 1e-12);
  EXPECT_NEAR(hemisphere_uv(z).y(), -0.659237922330169, 1e-12);
}

TEST(TextureMap, DomeAroundAnObjectAndImageCoordinates) {
  const PhyxelSet box = lattice_box(Vec3(-0.02, -0.01, 0.1), Vec3(0.02, 0.01, 0.12), 0.005);
  const Dome dome = fit_dome(box.rest);
  // Axis +z through the centre of the box, the sphere's centre at its bottom.
  EXPECT_TRUE(dome.centre.isApprox(Vec3(0, 0, 0.1), 1e-12));
  EXPECT_TRUE(dome.axis.isApprox(Vec3::UnitZ()));
  for (const Vec3& x : box.rest) {
    EXPECT_LT((x - dome.centre).norm(), dome.radius);
    const Eigen::Vector2d st = dome_texcoord(dome, x);
    EXPECT_GE(st.x(), -1e-12);
    EXPECT_LE(st.x(), 1.0 + 1e-12);
    EXPECT_GE(st.y(), -1e-12);
    EXPECT_LE(st.y(), 1.0 + 1e-12);
  }
  // The top centre maps to the pole, the image centre; +x to the right, +y up in the image.
  const Eigen::Vector2d top = dome_texcoord(dome, Vec3(0, 0, 0.12));
  EXPECT_NEAR(top.x(), 0.5, 1e-12);
  EXPECT_NEAR(top.y(), 0.5, 1e-12);
  EXPECT_GT(dome_texcoord(dome, Vec3(0.01, 0, 0.12)).x(), 0.5);
  EXPECT_LT(dome_texcoord(dome, Vec3(0, 0.01, 0.12)).y(), 0.5);
  // The tangential gradient predicts a small step along the surface to first order: the
  // error shrinks 4 times when the step halves.
  const Vec3 x(0.01, 0.005, 0.12), n = Vec3::UnitZ(), step(2e-4, -1e-4, 0);
  const Eigen::Matrix<double, 2, 3> g = dome_texcoord_gradient(dome, x, n);
  EXPECT_NEAR((g * n).norm(), 0.0, 1e-12);
  auto error = [&](double f) {
    return (dome_texcoord(dome, x) + g * (f * step) - dome_texcoord(dome, x + f * step)).norm();
  };
  EXPECT_LT(error(1), 0.01 * (g * step).norm());
  EXPECT_NEAR(error(1) / error(0.5), 4.0, 0.2);
}

TEST(TextureMap, SurfelTableHoldsTheDomeCoordinates) {
  const PhyxelSet box = lattice_box(Vec3(0, 0, 0), Vec3(0.02, 0.02, 0.01), 0.005);
  const SurfelTable table = build_surfel_table(box);
  const Dome dome = fit_dome(box.rest);
  size_t surface = 0;
  for (size_t i = 0; i < box.size(); ++i) surface += (box.flags[i] & kSurface) != 0;
  ASSERT_EQ(table.surfels.size(), surface);
  for (const layout::SurfelStatic& s : table.surfels) {
    const Eigen::Vector2d st = dome_texcoord(dome, box.rest[s.index]);
    EXPECT_NEAR(s.ds_dx.w, st.x(), 1e-6);
    EXPECT_NEAR(s.dt_dx.w, st.y(), 1e-6);
    EXPECT_FLOAT_EQ(s.radius, 0.004f);
    EXPECT_FLOAT_EQ(s.support, 0.01f);
  }
}

class TextureFile : public ::testing::Test {
 protected:
  std::filesystem::path path(const std::string& name) {
    return test::test_out_dir() /
           (::testing::UnitTest::GetInstance()->current_test_info()->name() + ("_" + name));
  }
};

TEST_F(TextureFile, PngRoundTrip) {
  RgbaImage image(3, 2);
  for (uint32_t y = 0; y < 2; ++y)
    for (uint32_t x = 0; x < 3; ++x) {
      uint8_t* p = image.at(x, y);
      p[0] = uint8_t(40 * x);
      p[1] = uint8_t(100 * y);
      p[2] = 7;
      p[3] = 255;
    }
  write_png(path("t.png"), image);
  const RgbaImage back = load_image(path("t.png"), "scene.json: render.texture");
  EXPECT_EQ(back.width, 3u);
  EXPECT_EQ(back.height, 2u);
  EXPECT_EQ(back.pixels, image.pixels);
}

// The PNG writer deflates with zlib and filters every row by Up (third_party/stb_impl.cpp):
// random bytes (nothing to compress) and smooth gradients both come back exactly, alpha too.
TEST_F(TextureFile, PngRoundTripOfNoiseAndGradientsIsExact) {
  RgbaImage image(257, 131);
  uint32_t state = 12345;
  for (uint32_t y = 0; y < image.height; ++y)
    for (uint32_t x = 0; x < image.width; ++x) {
      uint8_t* p = image.at(x, y);
      state = state * 1664525u + 1013904223u;
      const bool noisy = x < image.width / 2;
      p[0] = noisy ? uint8_t(state >> 24) : uint8_t(x);
      p[1] = noisy ? uint8_t(state >> 16) : uint8_t(y * 2);
      p[2] = noisy ? uint8_t(state >> 8) : uint8_t(x + y);
      p[3] = noisy ? uint8_t(state) : 255;
    }
  write_png(path("noise.png"), image);
  const RgbaImage back = load_image(path("noise.png"), "noise.png");
  ASSERT_EQ(back.width, image.width);
  ASSERT_EQ(back.height, image.height);
  EXPECT_EQ(back.pixels, image.pixels);
}

TEST_F(TextureFile, BadFilesGiveOneLineNamingTheKeyAndFile) {
  const std::string context = "scenes/x.json: render.texture";
  auto message = [&](const std::filesystem::path& file) {
    return phyxel::test::error_of<SceneError>([&] { load_image(file, context); });
  };
  const std::string missing = message(path("missing.png"));
  EXPECT_NE(missing.find(context + ": texture file \""), std::string::npos) << missing;
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;

  std::ofstream(path("empty.png")).close();
  const std::string empty = message(path("empty.png"));
  EXPECT_NE(empty.find("zero-size"), std::string::npos) << empty;

  std::ofstream(path("text.png")) << "not an image at all";
  const std::string text = message(path("text.png"));
  EXPECT_NE(text.find("cannot decode"), std::string::npos) << text;
  EXPECT_NE(text.find("text.png"), std::string::npos) << text;

  // A PNG whose header says 0 x 0 pixels.
  const unsigned char zero[] = {0x89, 'P', 'N', 'G', 0x0d, 0x0a, 0x1a, 0x0a, 0, 0, 0,
                                13,   'I', 'H', 'D', 'R',  0,    0,    0,    0, 0, 0,
                                0,    0,   8,   6,   0,    0,    0,    0,    0, 0, 0};
  std::ofstream(path("zero.png"), std::ios::binary)
      .write(reinterpret_cast<const char*>(zero), sizeof zero);
  const std::string z = message(path("zero.png"));
  EXPECT_NE(z.find(context), std::string::npos) << z;
  EXPECT_NE(z.find("zero.png"), std::string::npos) << z;
  for (const std::string& m : {missing, empty, text, z}) {
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find("allowed a PNG or JPEG image"), std::string::npos) << m;
  }
}

TEST(ProceduralTexture, TissueColoursWithVessels) {
  const RgbaImage t = procedural_tissue_texture(128);
  ASSERT_EQ(t.width, 128u);
  size_t vessel = 0, pink = 0;
  for (uint32_t y = 0; y < t.height; ++y)
    for (uint32_t x = 0; x < t.width; ++x) {
      const uint8_t* p = t.at(x, y);
      EXPECT_EQ(p[3], 255);
      EXPECT_GT(p[0], p[1]);  // reddish everywhere
      vessel += p[1] < 60;
      pink += p[1] > 100;
    }
  EXPECT_GT(pink, t.width * t.height / 2);
  EXPECT_GT(vessel, t.width * t.height / 200);
  EXPECT_EQ(procedural_tissue_texture(128).pixels, t.pixels);  // deterministic
}

}  // namespace
}  // namespace phyxel::render
