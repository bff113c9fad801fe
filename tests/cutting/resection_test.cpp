// What a cut frees (engine/surgery/resection.h): a beam with an inclusion near its tip, cut
// through near its clamp, frees the tip piece with all of the inclusion in it; a slit frees
// nothing; a cut through the inclusion leaves part of it attached.
#include <gtest/gtest.h>

#include "cutting_fixtures.h"
#include "engine/surgery/resection.h"

namespace phyxel {
namespace {

using test::clamped_beam;
using test::crossing_scalpel;
using test::ToolStepper;

Scene beam_with_tumour() {
  Scene scene = clamped_beam();
  Inclusion tumour;
  tumour.name = "tumour";
  tumour.shape.type = Shape::Type::Sphere;
  tumour.shape.center = Vec3(0.03, 0.005, 0.005);
  tumour.shape.radius = 0.004;
  tumour.material = test::tissue(2e5, 0.3, 0);
  tumour.material.density = 1100;
  scene.objects[0].inclusions.push_back(tumour);
  return scene;
}

std::vector<uint8_t> alive(const CpuSolver<double>& s) {
  std::vector<uint8_t> a(s.pair_weights().size());
  for (size_t k = 0; k < a.size(); ++k) a[k] = s.pair_weights()[k] != 0;
  return a;
}

Resection cut_and_measure(const Scene& scene, double x_cut, double tip_z, double length) {
  Scene with = scene;
  with.tools.push_back(crossing_scalpel(x_cut, tip_z, length, 0.0, 0.016));
  const PhyxelSet set = sample_scene(with);
  CpuSolver<double> solver(set, with.simulation.gravity);
  ToolStepper<double> run(solver, with.tools, with.simulation.dt);
  run.run(220);
  return measure_resection(with, set, solver.neighbours(), alive(solver));
}

TEST(Resection, ACutThroughTheBeamFreesTheTipWithTheWholeTumour) {
  const Scene scene = beam_with_tumour();
  const PhyxelSet set = sample_scene(scene);
  double tumour = 0, beyond = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    if (set.material[i] == 1)
      tumour += set.mass[i];
    else if (set.rest[i].x() > 0.019)
      beyond += set.mass[i];
  }
  const Resection r = cut_and_measure(scene, 0.019, -0.003, 0.016);
  EXPECT_EQ(r.pieces, 1u);
  ASSERT_EQ(r.inclusions.size(), 1u);
  const InclusionRemoval& t = r.inclusions[0];
  EXPECT_EQ(t.name, "tumour");
  EXPECT_DOUBLE_EQ(t.mass, tumour);
  EXPECT_DOUBLE_EQ(t.removed, tumour);
  EXPECT_TRUE(t.whole);
  EXPECT_NEAR(t.healthy_removed, beyond, 1e-12);
  EXPECT_NEAR(r.freed_mass, tumour + beyond, 1e-12);
}

TEST(Resection, ASlitFreesNothingAndACutThroughTheTumourLeavesPartOfIt) {
  const Scene scene = beam_with_tumour();
  const Resection slit = cut_and_measure(scene, 0.019, 0.005, 0.008);
  EXPECT_EQ(slit.pieces, 0u);
  EXPECT_EQ(slit.inclusions[0].removed, 0.0);
  EXPECT_FALSE(slit.inclusions[0].whole);
  const Resection through = cut_and_measure(scene, 0.029, -0.003, 0.016);
  EXPECT_EQ(through.pieces, 1u);
  EXPECT_GT(through.inclusions[0].removed, 0.0);
  EXPECT_LT(through.inclusions[0].removed, through.inclusions[0].mass);
  EXPECT_FALSE(through.inclusions[0].whole);
}

}  // namespace
}  // namespace phyxel
