// Box sampling: lattice counts, quadrature volumes, surface flags and normals.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/sampling/phyxel_set.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

constexpr double kS = 0.0025;

// The beam: 0.1 m x 0.02 m x 0.02 m at spacing 2.5 mm.
Scene beam(const Vec3& min = Vec3::Zero()) {
  return scene_of({object("beam", box(min, min + Vec3(0.1, 0.02, 0.02)), kS)});
}

// How many of a point's coordinates lie on the box's faces.
int faces_touched(const Vec3& p, const Vec3& min, const Vec3& max) {
  int count = 0;
  for (int d = 0; d < 3; ++d)
    count += std::abs(p[d] - min[d]) < 1e-9 || std::abs(p[d] - max[d]) < 1e-9;
  return count;
}

TEST(BoxSampling, BeamHas41By9By9PhyxelsIncludingCorners) {
  const PhyxelSet set = sample_scene(beam());
  ASSERT_EQ(set.size(), 41u * 9u * 9u);
  // x fastest, then y, then z, starting at the min corner.
  EXPECT_EQ(set.rest[0], Vec3(0, 0, 0));
  EXPECT_NEAR(set.rest[1].x(), kS, 1e-15);
  EXPECT_NEAR(set.rest[41].y(), kS, 1e-15);
  EXPECT_NEAR((set.rest.back() - Vec3(0.1, 0.02, 0.02)).norm(), 0, 1e-15);
  ASSERT_EQ(set.objects.size(), 1u);
  EXPECT_EQ(set.objects[0].name, "beam");
  EXPECT_EQ(set.objects[0].first, 0u);
  EXPECT_EQ(set.objects[0].count, 3321u);
  EXPECT_EQ(set.objects[0].spacing, kS);
  EXPECT_EQ(set.objects[0].support_radius, 2 * kS);
  for (const std::vector<uint32_t>* v : {&set.material, &set.object, &set.flags})
    EXPECT_EQ(v->size(), set.size());
  EXPECT_EQ(set.volume.size(), set.size());
  EXPECT_EQ(set.mass.size(), set.size());
  EXPECT_EQ(set.normal.size(), set.size());
  EXPECT_EQ(set.splat_radius.size(), set.size());
  EXPECT_EQ(set.external_force.size(), set.size());
  EXPECT_EQ(set.initial_velocity.size(), set.size());
}

TEST(BoxSampling, OffsetBoxWithInexactCoordinatesKeepsTheCount) {
  // 0.013 + 0.1 is not exactly representable: the last layer must not be lost to rounding.
  const PhyxelSet set = sample_scene(beam(Vec3(0.013, -0.0371, 0.1)));
  EXPECT_EQ(set.size(), 41u * 9u * 9u);
  EXPECT_NEAR(total_volume(set), 0.1 * 0.02 * 0.02, 1e-12 * 4e-5);
}

TEST(BoxSampling, TotalVolumeIsExactAndFacesEdgesCornersAreFractions) {
  const PhyxelSet set = sample_scene(beam());
  EXPECT_NEAR(total_volume(set), 0.1 * 0.02 * 0.02, 1e-12 * 4e-5);
  const double cell = kS * kS * kS;
  const Vec3 max(0.1, 0.02, 0.02);
  int by_faces[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < set.size(); ++i) {
    const int faces = faces_touched(set.rest[i], Vec3::Zero(), max);
    ++by_faces[faces];
    EXPECT_DOUBLE_EQ(set.volume[i], cell / (1 << faces)) << "phyxel " << i;
    EXPECT_DOUBLE_EQ(set.mass[i], 1000 * set.volume[i]);
  }
  EXPECT_EQ(by_faces[0], 39 * 7 * 7);
  EXPECT_EQ(by_faces[1], 2 * (39 * 7 + 39 * 7 + 7 * 7));
  EXPECT_EQ(by_faces[2], 4 * (39 + 7 + 7));
  EXPECT_EQ(by_faces[3], 8);
}

TEST(BoxSampling, SurfaceFlagsNormalsAndSplatsFollowTheFaces) {
  const PhyxelSet set = sample_scene(beam());
  const Vec3 max(0.1, 0.02, 0.02);
  int surface = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    Vec3 expected = Vec3::Zero();
    for (int d = 0; d < 3; ++d) {
      if (std::abs(p[d]) < 1e-9) expected[d] = -1;
      if (std::abs(p[d] - max[d]) < 1e-9) expected[d] = 1;
    }
    const bool on_surface = expected.squaredNorm() > 0;
    EXPECT_EQ((set.flags[i] & kSurface) != 0, on_surface) << "phyxel " << i;
    EXPECT_EQ(set.flags[i] & kFixed, 0u);
    if (on_surface) {
      ++surface;
      EXPECT_NEAR((set.normal[i] - expected.normalized()).norm(), 0, 1e-12) << "phyxel " << i;
      EXPECT_DOUBLE_EQ(set.splat_radius[i], 0.8 * kS);
    } else {
      EXPECT_EQ(set.normal[i], Vec3::Zero());
      EXPECT_EQ(set.splat_radius[i], 0);
    }
  }
  EXPECT_EQ(surface, 41 * 9 * 9 - 39 * 7 * 7);
  // The corner at the min gets the diagonal (-1, -1, -1) / sqrt(3).
  EXPECT_NEAR(set.normal[0].x(), -1 / std::sqrt(3.0), 1e-12);
}

TEST(BoxSampling, SideThatIsNotAMultipleOfTheSpacing) {
  // 10.5 mm at 2.5 mm: points at 0..10 mm; the last layer is surface with a +x normal and
  // its cell is cut by the face at 10.5 mm.
  const PhyxelSet set =
      sample_scene(scene_of({object("b", box(Vec3::Zero(), Vec3(0.0105, 0.01, 0.01)), kS)}));
  ASSERT_EQ(set.size(), 5u * 5u * 5u);
  const size_t i = 4 + 5 * (2 + 5 * 2);  // x = 10 mm, y = z = 5 mm
  EXPECT_NEAR(set.rest[i].x(), 0.01, 1e-15);
  EXPECT_TRUE(set.flags[i] & kSurface);
  EXPECT_NEAR((set.normal[i] - Vec3::UnitX()).norm(), 0, 1e-12);
  // Sub-cell centres at 10 mm +- 0.3125 mm are inside, those at +0.9375 mm are not.
  EXPECT_DOUBLE_EQ(set.volume[i], 0.75 * kS * kS * kS);
  EXPECT_NEAR(total_volume(set), 0.0105 * 0.01 * 0.01, 0.02 * 0.0105 * 0.01 * 0.01);
}

TEST(BoxSampling, ObjectsFollowEachOtherWithTheirOwnSpacing) {
  ObjectDesc a = object("a", box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01)), kS);
  ObjectDesc b = object("b", box(Vec3(1, 0, 0), Vec3(1.02, 0.01, 0.01)), 0.005);
  b.material = tissue(2000);
  b.initial_velocity = Vec3(0, 0, -0.5);
  b.support_radius = 0;  // unset: twice the spacing
  const PhyxelSet set = sample_scene(scene_of({a, b}));
  ASSERT_EQ(set.objects.size(), 2u);
  EXPECT_EQ(set.objects[0].count, 125u);
  EXPECT_EQ(set.objects[1].first, 125u);
  EXPECT_EQ(set.objects[1].count, 5u * 3u * 3u);
  EXPECT_EQ(set.objects[1].spacing, 0.005);
  EXPECT_EQ(set.objects[1].support_radius, 0.01);
  ASSERT_EQ(set.size(), 125u + 45u);
  ASSERT_EQ(set.materials.size(), 2u);
  EXPECT_EQ(set.materials[1].density, 2000);
  for (size_t i = 0; i < set.size(); ++i) {
    const uint32_t k = i < 125 ? 0 : 1;
    EXPECT_EQ(set.object[i], k);
    EXPECT_EQ(set.material[i], k);
    EXPECT_EQ(set.initial_velocity[i], k == 0 ? Vec3::Zero() : Vec3(0, 0, -0.5));
    EXPECT_EQ(set.external_force[i], Vec3::Zero());
  }
  double mass_b = 0;
  for (size_t i = 125; i < set.size(); ++i) mass_b += set.mass[i];
  EXPECT_NEAR(mass_b, 2000 * 0.02 * 0.01 * 0.01, 1e-12 * mass_b);
}

TEST(BoxSampling, ABoxThinnerThanTheSpacingIsOneLayerAndRefused) {
  // One layer of 5 x 5 phyxels: every moment matrix is singular across the plate (no stiffness
  // across it), so sampling refuses it (tests/sampling/small_body_test.cpp has the rest).
  try {
    sample_scene(scene_of({object("plate", box(Vec3::Zero(), Vec3(0.01, 0.01, 0.001)), kS)}));
    FAIL() << "a plate one phyxel thick was accepted";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "objects[0] \"plate\" (box 10 x 10 x 1 mm): samples to 25 phyxels"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("all in one plane"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace phyxel::test
