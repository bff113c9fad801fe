// refine_scene (`--refine K`): spacing and support radius divided by K, nothing else changed.
#include <gtest/gtest.h>

#include <stdexcept>

#include "engine/scene/scene.h"

namespace phyxel {
namespace {

const std::filesystem::path kScalpel =
    std::filesystem::path(PHYXEL_SOURCE_DIR) / "scenes/scalpel_cut.json";

TEST(RefineScene, DividesSpacingAndSupportRadiusOnly) {
  const Scene before = load_scene(kScalpel);
  Scene after = before;
  refine_scene(after, 1.5);
  EXPECT_EQ(after.refine, 1.5);
  ASSERT_EQ(after.objects.size(), before.objects.size());
  for (size_t o = 0; o < before.objects.size(); ++o) {
    EXPECT_DOUBLE_EQ(after.objects[o].spacing, before.objects[o].spacing / 1.5);
    EXPECT_DOUBLE_EQ(after.objects[o].support_radius, before.objects[o].support_radius / 1.5);
    EXPECT_EQ(after.objects[o].material.young, before.objects[o].material.young);
    EXPECT_EQ(after.objects[o].shape.max, before.objects[o].shape.max);
  }
  EXPECT_EQ(after.simulation.dt, before.simulation.dt);
  EXPECT_EQ(after.simulation.steps, before.simulation.steps);
  ASSERT_EQ(after.tools.size(), before.tools.size());
  for (size_t t = 0; t < before.tools.size(); ++t) {
    EXPECT_EQ(after.tools[t].shape.radius, before.tools[t].shape.radius);
    EXPECT_EQ(after.tools[t].blade.reach, before.tools[t].blade.reach);
    ASSERT_EQ(after.tools[t].path.size(), before.tools[t].path.size());
    for (size_t k = 0; k < before.tools[t].path.size(); ++k)
      EXPECT_EQ(after.tools[t].path[k].position, before.tools[t].path[k].position);
  }
  refine_scene(after, 2);  // refinements multiply
  EXPECT_EQ(after.refine, 3);
  EXPECT_DOUBLE_EQ(after.objects[0].spacing, before.objects[0].spacing / 3);
}

TEST(RefineScene, RefusesAFactorBelowOneOrNotFinite) {
  Scene scene = load_scene(kScalpel);
  for (const double k : {0.5, 0.0, -2.0, kMaxRefine * 2, std::nan("")})
    EXPECT_THROW(refine_scene(scene, k), std::invalid_argument) << k;
  EXPECT_EQ(scene.refine, 1);
}

}  // namespace
}  // namespace phyxel
