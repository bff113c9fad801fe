// Inclusions, fixed regions, loads and the errors that name their JSON paths.
#include <gtest/gtest.h>

#include <cmath>

#include "engine/sampling/phyxel_set.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

constexpr double kRegionSpacing = 0.0025;

ObjectDesc region_beam() {
  return object("beam", box(Vec3::Zero(), Vec3(0.1, 0.02, 0.02)), kRegionSpacing);
}

Inclusion inclusion(const std::string& name, const Shape& shape, double density) {
  Inclusion inc;
  inc.name = name;
  inc.shape = shape;
  inc.material = tissue(density);
  return inc;
}

TEST(Inclusions, MaterialsAreObjectsThenInclusionsAndLaterInclusionsWin) {
  ObjectDesc a = region_beam();
  // A tumour, and a vessel box that overlaps it at x >= 0.05.
  a.inclusions.push_back(inclusion("tumour", sphere(Vec3(0.05, 0.01, 0.01), 0.006), 1100));
  a.inclusions.push_back(
      inclusion("vessel", box(Vec3(0.05, 0.0, 0.0075), Vec3(0.1, 0.02, 0.0125)), 1200));
  ObjectDesc b = object("b", box(Vec3(1, 0, 0), Vec3(1.01, 0.01, 0.01)), kRegionSpacing);
  b.material = tissue(900);
  b.inclusions.push_back(inclusion("core", box(Vec3(1, 0, 0), Vec3(1.005, 0.01, 0.01)), 1300));
  const PhyxelSet set = sample_scene(scene_of({a, b}));
  // objects: 0 beam, 1 b; then beam's tumour 2, vessel 3; then b's core 4.
  ASSERT_EQ(set.materials.size(), 5u);
  const double densities[] = {1000, 900, 1100, 1200, 1300};
  for (int m = 0; m < 5; ++m) EXPECT_EQ(set.materials[m].density, densities[m]);
  int in_tumour = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    uint32_t expected = set.object[i];
    if (set.object[i] == 0) {
      if ((p - Vec3(0.05, 0.01, 0.01)).norm() <= 0.006 + 1e-12) expected = 2, ++in_tumour;
      if (p.x() >= 0.05 - 1e-12 && p.z() >= 0.0075 - 1e-12 && p.z() <= 0.0125 + 1e-12) expected = 3;
    } else if (p.x() <= 1.005 + 1e-12) {
      expected = 4;
    }
    EXPECT_EQ(set.material[i], expected) << "phyxel " << i;
    EXPECT_DOUBLE_EQ(set.mass[i], densities[expected] * set.volume[i]);
  }
  EXPECT_EQ(in_tumour, 57);  // sites within 2.4 s: |n|^2 <= 5
  // The tumour's centre is inside the vessel too: the later inclusion wins.
  const size_t centre = 20 + 41 * (4 + 9 * 4);
  EXPECT_EQ(set.rest[centre], Vec3(0.05, 0.01, 0.01));
  EXPECT_EQ(set.material[centre], 3u);
}

TEST(Fixed, PhyxelsInAnyFixedRegionAreFixed) {
  ObjectDesc a = region_beam();
  a.fixed.push_back(box(Vec3(-1, -1, -1), Vec3(0, 1, 1)));                 // the x = 0 face
  a.fixed.push_back(sphere(Vec3(0.1, 0.02, 0.02), 0.5 * kRegionSpacing));  // one corner
  const PhyxelSet set = sample_scene(scene_of({a}));
  int fixed = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    const bool expected = p.x() == 0 || (p - Vec3(0.1, 0.02, 0.02)).norm() < 1e-12;
    EXPECT_EQ((set.flags[i] & kFixed) != 0, expected) << "phyxel " << i;
    fixed += expected;
  }
  EXPECT_EQ(fixed, 81 + 1);
}

TEST(Loads, ForceIsSpreadByVolumeAndSumsToTheLoad) {
  ObjectDesc a = region_beam();
  Load end;  // the x = 0.1 end face: 9 x 9 phyxels of volume s^3/2, s^3/4, s^3/8
  end.region = box(Vec3(0.1, -1, -1), Vec3(1, 1, 1));
  end.force = Vec3(0.3, -2.0, 0.7);
  Load top;  // overlaps the end face on its z = 0.02 edge
  top.region = box(Vec3(0.05, 0, 0.02), Vec3(0.1, 0.02, 0.02));
  top.force = Vec3(0, 0, -1.5);
  a.loads = {end, top};
  const PhyxelSet set = sample_scene(scene_of({a}));
  Vec3 total = Vec3::Zero();
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3& p = set.rest[i];
    Vec3 expected = Vec3::Zero();
    // Region volumes: the end face 0.02 x 0.02 x s/2; the top strip (x = 0.05 .. 0.1: 20.5
    // cells, as the x = 0.05 cell is whole) 20.5 s x 0.02 x s/2.
    if (std::abs(p.x() - 0.1) < 1e-12)
      expected += end.force * set.volume[i] / (0.02 * 0.02 * kRegionSpacing / 2);
    if (p.x() >= 0.05 - 1e-12 && std::abs(p.z() - 0.02) < 1e-12)
      expected += top.force * set.volume[i] / (20.5 * kRegionSpacing * 0.02 * kRegionSpacing / 2);
    EXPECT_NEAR((set.external_force[i] - expected).norm(), 0, 1e-12) << "phyxel " << i;
    total += set.external_force[i];
  }
  EXPECT_NEAR((total - end.force - top.force).norm(), 0, 1e-13);
}

TEST(SamplingErrors, FixedRegionWithoutPhyxelsNamesItsPath) {
  ObjectDesc a = region_beam();
  ObjectDesc b = object("b", box(Vec3(1, 0, 0), Vec3(1.01, 0.01, 0.01)), kRegionSpacing);
  b.fixed.push_back(box(Vec3(1, 0, 0), Vec3(1.01, 0.01, 0)));
  b.fixed.push_back(box(Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1)));  // covers only object a
  const std::string message = scene_error([&] { sample_scene(scene_of({a, b})); });
  EXPECT_NE(message.find("test_scene.json: objects[1].fixed[1]: "), std::string::npos) << message;
  EXPECT_NE(message.find("no phyxel"), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST(SamplingErrors, LoadRegionWithoutPhyxelsNamesItsPath) {
  ObjectDesc a = region_beam();
  a.loads.resize(2);
  a.loads[0].region = box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01));
  a.loads[1].region = sphere(Vec3(0.05, 0.05, 0.05), 0.01);
  a.loads[1].force = Vec3(1, 0, 0);
  const std::string message = scene_error([&] { sample_scene(scene_of({a})); });
  EXPECT_NE(message.find("test_scene.json: objects[0].loads[1].region: "), std::string::npos)
      << message;
}

TEST(SamplingErrors, InclusionWithoutPhyxelsNamesItsPath) {
  ObjectDesc a = region_beam();
  a.inclusions.push_back(inclusion("tumour", sphere(Vec3(0.05, 0.01, 0.01), 0.004), 1100));
  // Between lattice points: no site within 1 mm of (1.25, 1.25, 1.25) mm.
  a.inclusions.push_back(inclusion("speck", sphere(Vec3(0.00125, 0.00125, 0.00125), 0.001), 1));
  const std::string message = scene_error([&] { sample_scene(scene_of({a})); });
  EXPECT_NE(message.find("test_scene.json: objects[0].inclusions[1].shape: "), std::string::npos)
      << message;
}

TEST(SamplingErrors, MeshShapeWithoutASurface) {
  ObjectDesc a = region_beam();
  Shape unloaded;
  unloaded.type = Shape::Type::Mesh;
  unloaded.path = "liver.obj";
  a.fixed.push_back(unloaded);
  const std::string message = scene_error([&] { sample_scene(scene_of({a})); });
  EXPECT_NE(message.find("test_scene.json: objects[0].fixed[0]: the mesh shape has no loaded"),
            std::string::npos)
      << message;
}

TEST(SamplingErrors, ObjectWithoutPhyxelsNamesShapeAndSpacing) {
  ObjectDesc a = region_beam();
  ObjectDesc b = object("inverted", box(Vec3(0.01, 0, 0), Vec3(0, 0.01, 0.01)), kRegionSpacing);
  const std::string message = scene_error([&] { sample_scene(scene_of({a, b})); });
  EXPECT_NE(message.find("test_scene.json: objects[1].shape: "), std::string::npos) << message;
  EXPECT_NE(message.find("objects[1].spacing"), std::string::npos) << message;
}

TEST(SamplingErrors, BadSpacingAndHugeLatticesAreRefused) {
  ObjectDesc a = region_beam();
  a.spacing = 0;
  std::string message = scene_error([&] { sample_scene(scene_of({a})); });
  EXPECT_NE(message.find("objects[0].spacing: "), std::string::npos) << message;
  a.spacing = 1e-7;  // 1e6 x 2e5 x 2e5 sites
  message = scene_error([&] { sample_scene(scene_of({a})); });
  EXPECT_NE(message.find("objects[0].spacing: "), std::string::npos) << message;
  EXPECT_NE(message.find("larger spacing"), std::string::npos) << message;
}

}  // namespace
}  // namespace phyxel::test
