// The cutting force of eqs 21-26 (engine/surgery/cut_feedback.h): the split of the blade's force
// against its plane, the penetration depth and the friction of the cut faces, per substep and as
// a run records it (ToolTrack::fold).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "cutting_fixtures.h"
#include "engine/surgery/cut_feedback.h"

namespace phyxel {
namespace {

using test::clamped_beam;
using test::crossing_scalpel;

Blade vertical_blade(double length) {
  Blade b;
  b.length = length;
  b.edge = Vec3::UnitY();
  b.reference_axis = Vec3::UnitZ();
  return b;
}

ToolContactSample felt(const Vec3& force, double axial_min, double axial_max) {
  ToolContactSample s;
  s.force = force;
  s.contacts = 3;
  s.axial_min = axial_min;
  s.axial_max = axial_max;
  return s;
}

// A vertical blade moved along +y: its plane is y-z, its normal x.
TEST(CutFeedback, SplitsTheForceAgainstTheBladePlaneAndDragsAgainstTheMotion) {
  const Blade blade = vertical_blade(0.02);
  const ToolMotion m{{Vec3(0, 0, 0), Vec3::UnitZ()}, {Vec3(0, 1e-4, 0), Vec3::UnitZ()}};
  const double mu = 0.3;
  const CutFeedback f = cut_feedback(blade, mu, m, felt(Vec3(0.03, -0.4, 0.1), 0.002, 0.012));
  EXPECT_NEAR(f.normal, 0.03, 1e-15);                    // |F_p| = |F_x . n|
  EXPECT_NEAR(f.in_plane, std::hypot(0.4, 0.1), 1e-15);  // |F_l|
  EXPECT_NEAR(f.theta, std::atan2(f.in_plane, 0.03), 1e-15);
  EXPECT_NEAR(f.cut_force, 0.4, 1e-15);  // the edge (+y) pressed back
  EXPECT_NEAR(f.depth, 0.010, 1e-15);
  const double drag = mu * (f.in_plane * 0.010 / 0.02 + 0.03);  // eqs 24-26
  EXPECT_NEAR((f.friction - Vec3(0, -drag, 0)).norm(), 0.0, 1e-15);
}

TEST(CutFeedback, PartsAndFrictionHoldTheirRelationsForAnyPoseAndForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto random_unit = [&] { return Vec3(u(rng), u(rng), u(rng)).normalized(); };
  for (int k = 0; k < 1000; ++k) {
    const Vec3 axis = random_unit();
    Blade blade = vertical_blade(0.01 + 0.02 * std::abs(u(rng)));
    blade.reference_axis = axis;
    blade.edge = axis.cross(random_unit()).normalized();
    const ToolPose from{Vec3(u(rng), u(rng), u(rng)) * 0.01, axis};
    const Vec3 turned = (axis + 0.05 * random_unit()).normalized();
    const ToolPose to{from.position + 1e-4 * random_unit(), turned};
    const Vec3 force = random_unit() * std::abs(u(rng));
    const double mu = std::abs(u(rng));
    const CutFeedback f = cut_feedback(blade, mu, {from, to}, felt(force, -0.01, 0.05));
    // F_l and F_p are orthogonal parts of F_x (eqs 21-22).
    EXPECT_NEAR(f.in_plane * f.in_plane + f.normal * f.normal, force.squaredNorm(), 1e-12);
    EXPECT_NEAR(f.in_plane, force.norm() * std::sin(f.theta), 1e-12);
    EXPECT_NEAR(f.normal, force.norm() * std::cos(f.theta), 1e-12);
    EXPECT_NEAR(f.depth, blade.length, 1e-15);  // the range covers the whole blade
    // The drag has the magnitude of eqs 24-26, lies in the blade's plane (perpendicular to
    // the normal part) and opposes the sliding of the blade's middle.
    EXPECT_NEAR(f.friction.norm(), mu * (f.in_plane + f.normal), 1e-12);
    const Vec3 mid_motion =
        to.position + 0.5 * blade.length * to.axis - from.position - 0.5 * blade.length * axis;
    EXPECT_LE(f.friction.dot(mid_motion), 0.0);
    EXPECT_NEAR(f.friction.dot(to.axis.cross(swept_quad(blade, from, to, 0).edge).normalized()),
                0.0, 1e-12);
  }
}

TEST(CutFeedback, DepthIsTheBladeInContactAndNothingIsFeltWithoutContactOrSliding) {
  const Blade blade = vertical_blade(0.02);
  const ToolMotion moved{{Vec3::Zero(), Vec3::UnitZ()}, {Vec3(0, 1e-4, 0), Vec3::UnitZ()}};
  const Vec3 force(0.01, -0.2, 0);
  // The contacts' range is clamped to the blade: the shaft above it does not count.
  EXPECT_NEAR(cut_feedback(blade, 0.2, moved, felt(force, -0.001, 0.035)).depth, 0.02, 1e-15);
  EXPECT_NEAR(cut_feedback(blade, 0.2, moved, felt(force, 0.005, 0.005)).depth, 0.0, 1e-15);
  // No contact: nothing at all.
  const CutFeedback none = cut_feedback(blade, 0.2, moved, ToolContactSample{});
  EXPECT_EQ(none.cut_force, 0.0);
  EXPECT_EQ(none.depth, 0.0);
  EXPECT_EQ(none.friction, Vec3::Zero());
  // No friction coefficient, or a blade at rest: no drag, but the split is still reported.
  const CutFeedback smooth = cut_feedback(blade, 0.0, moved, felt(force, 0, 0.01));
  EXPECT_EQ(smooth.friction, Vec3::Zero());
  EXPECT_GT(smooth.in_plane, 0.0);
  const ToolMotion rest{moved.to, moved.to};
  const CutFeedback still = cut_feedback(blade, 0.2, rest, felt(force, 0, 0.01));
  EXPECT_EQ(still.friction, Vec3::Zero());
  EXPECT_NEAR(still.normal, 0.01, 1e-15);
}

// A blade (tip 4 mm above the beam's bottom, 16 mm long) cuts across a 10 mm beam: while it is
// in the tissue it is in contact over the 6 mm above its tip, the cut faces drag it back
// against its motion (+y), and the hand feels the reaction plus that drag.
TEST(CutFeedback, ARunRecordsTheDepthAndTheDragOfABladeCuttingABeam) {
  Scene scene = clamped_beam();
  const double dt = scene.simulation.dt;
  ToolDesc scalpel = crossing_scalpel(0.02, 0.004, 0.016, 0.0, 0.016);
  scalpel.friction = 0.3;
  scene.tools.push_back(scalpel);
  const PhyxelSet set = sample_scene(scene);
  CpuSolver<double> solver(set, scene.simulation.gravity);
  solver.set_tools(contact_tools(scene.tools));
  ToolTrack track(scene.tools, {});
  int in_tissue = 0, dragged = 0;
  for (int64_t step = 0; step < 160; ++step) {
    solver.set_tool_motion(track.motions(step, 1, dt), dt);
    solver.step(dt);
    const ToolStepRecord r = track.fold(solver.tool_samples(), 1, 1)[0];
    EXPECT_EQ(r.hand_force(), r.force + r.cut.friction);
    const double y = r.pose.position.y();
    if (y < 0.002 || y > 0.008) continue;  // mid-beam only
    ++in_tissue;
    EXPECT_NEAR(r.cut.depth, 0.006, 0.002) << "step " << step;
    EXPECT_LE(r.cut.friction.y(), 0.0) << "step " << step;
    if (r.cut.friction.y() < 0) ++dragged;
    EXPECT_NEAR(r.cut.friction.norm(), 0.3 * (r.cut.in_plane * r.cut.depth / 0.016 + r.cut.normal),
                1e-12);
    EXPECT_NEAR(r.cut.in_plane * r.cut.in_plane + r.cut.normal * r.cut.normal,
                r.force.squaredNorm(), 1e-9 * r.force.squaredNorm() + 1e-30);
  }
  EXPECT_GT(in_tissue, 50);
  EXPECT_GT(dragged, 25);  // substeps in which some phyxel touched the thin blade
  const ToolRunStats& st = track.stats()[0];
  EXPECT_NEAR(st.max_depth, 0.006, 0.002);
  EXPECT_GT(st.max_friction, 0.0);
  EXPECT_GE(st.max_feedback, st.max_friction);
  EXPECT_GT(solver.severed_count(), 50u);
}

}  // namespace
}  // namespace phyxel
