// The tool model's math (engine/geometry/tool.h): path poses, the shortest rotation of the axis,
// the signed distance to sphere and capsule, the rigid carry of a point, and the bounds.
#include "engine/geometry/tool.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace phyxel {
namespace {

constexpr double kTol = 1e-14;

std::vector<ToolKey> two_keys() {
  return {{1.0, Vec3(0, 0, 0), Vec3::UnitZ()}, {3.0, Vec3(2, 4, 6), Vec3::UnitX()}};
}

Vec3 random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// --- pose_at ---

TEST(ToolPose, BeforeTheFirstKeyRestsAtIt) {
  for (double t : {-5.0, 0.0, 1.0}) {
    const ToolPose p = pose_at(two_keys(), t);
    EXPECT_EQ(p.position, Vec3(0, 0, 0)) << t;
    EXPECT_EQ(p.axis, Vec3::UnitZ()) << t;
  }
}

TEST(ToolPose, AfterTheLastKeyStaysThere) {
  for (double t : {3.0, 3.5, 1e9}) {
    const ToolPose p = pose_at(two_keys(), t);
    EXPECT_EQ(p.position, Vec3(2, 4, 6)) << t;
    EXPECT_EQ(p.axis, Vec3::UnitX()) << t;
  }
}

TEST(ToolPose, MidpointIsLinearInPositionAndHalfTheRotation) {
  const ToolPose p = pose_at(two_keys(), 2.0);
  EXPECT_NEAR((p.position - Vec3(1, 2, 3)).norm(), 0, kTol);
  EXPECT_NEAR((p.axis - Vec3(1, 0, 1) / std::sqrt(2.0)).norm(), 0, kTol);
  const ToolPose q = pose_at(two_keys(), 1.5);  // a quarter of the way
  EXPECT_NEAR((q.position - Vec3(0.5, 1, 1.5)).norm(), 0, kTol);
  EXPECT_NEAR(std::acos(q.axis.dot(Vec3::UnitZ())), M_PI / 8, 1e-12);
}

TEST(ToolPose, PicksTheSegmentOfTheTime) {
  const std::vector<ToolKey> path = {{0.0, Vec3(0, 0, 0), Vec3::UnitZ()},
                                     {1.0, Vec3(1, 0, 0), Vec3::UnitZ()},
                                     {2.0, Vec3(1, 1, 0), Vec3::UnitY()}};
  EXPECT_NEAR((pose_at(path, 0.5).position - Vec3(0.5, 0, 0)).norm(), 0, kTol);
  EXPECT_NEAR((pose_at(path, 1.0).position - Vec3(1, 0, 0)).norm(), 0, kTol);
  EXPECT_NEAR((pose_at(path, 1.0).axis - Vec3::UnitZ()).norm(), 0, kTol);
  EXPECT_NEAR((pose_at(path, 1.5).position - Vec3(1, 0.5, 0)).norm(), 0, kTol);
  EXPECT_NEAR((pose_at(path, 1.5).axis - Vec3(0, 1, 1) / std::sqrt(2.0)).norm(), 0, kTol);
}

TEST(ToolPose, OneKeyPathIsThatKeyAtAnyTime) {
  const std::vector<ToolKey> path = {{0.25, Vec3(0.1, 0.2, 0.3), Vec3(0, 1, 0)}};
  for (double t : {-1.0, 0.0, 0.25, 0.3, 100.0}) {
    const ToolPose p = pose_at(path, t);
    EXPECT_EQ(p.position, Vec3(0.1, 0.2, 0.3)) << t;
    EXPECT_EQ(p.axis, Vec3(0, 1, 0)) << t;
  }
}

// --- slerp_axis ---

TEST(ToolSlerp, MidpointOfXAndYIsTheirNormalisedSum) {
  const Vec3 m = slerp_axis(Vec3::UnitX(), Vec3::UnitY(), 0.5);
  EXPECT_NEAR((m - Vec3(1, 1, 0).normalized()).norm(), 0, kTol);
}

TEST(ToolSlerp, EndsAreTheInputs) {
  const Vec3 a = Vec3(1, 2, 3).normalized(), b = Vec3(-2, 0.5, 1).normalized();
  EXPECT_NEAR((slerp_axis(a, b, 0) - a).norm(), 0, kTol);
  EXPECT_NEAR((slerp_axis(a, b, 1) - b).norm(), 0, kTol);
  EXPECT_EQ(slerp_axis(a, a, 0.3), a);
}

TEST(ToolSlerp, StaysUnitAndTurnsAtConstantRateInThePlaneOfAB) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec3 a = random_unit(rng), b = random_unit(rng);
    const double theta = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
    const Vec3 plane = a.cross(b).normalized();
    for (double s = 0; s <= 1.0; s += 0.125) {
      const Vec3 v = slerp_axis(a, b, s);
      EXPECT_NEAR(v.norm(), 1, 1e-14);
      EXPECT_NEAR(std::acos(std::clamp(a.dot(v), -1.0, 1.0)), s * theta, 1e-7);
      EXPECT_NEAR(v.dot(plane), 0, 1e-12);  // the shortest rotation stays in the plane of a, b
    }
  }
}

TEST(ToolSlerp, OppositeVectorsTurnThroughAPerpendicular) {
  std::mt19937 rng(11);
  std::vector<Vec3> axes = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), -Vec3::UnitZ()};
  for (int i = 0; i < 20; ++i) axes.push_back(random_unit(rng));
  for (const Vec3& a : axes) {
    const Vec3 b = -a;
    const Vec3 m = slerp_axis(a, b, 0.5);
    EXPECT_NEAR(m.norm(), 1, 1e-14) << a.transpose();
    EXPECT_NEAR(m.dot(a), 0, 1e-12) << a.transpose();
    EXPECT_NEAR(m.dot(b), 0, 1e-12) << a.transpose();
    EXPECT_NEAR((slerp_axis(a, b, 1) - b).norm(), 0, 1e-12) << a.transpose();
    // A continuous turn at constant rate, not a jump from a to b.
    for (double s : {0.1, 0.25, 0.5, 0.75, 0.9}) {
      const Vec3 v = slerp_axis(a, b, s);
      EXPECT_NEAR(v.norm(), 1, 1e-14) << a.transpose() << " s " << s;
      EXPECT_NEAR(std::acos(std::clamp(a.dot(v), -1.0, 1.0)), s * M_PI, 1e-7)
          << a.transpose() << " s " << s;
    }
  }
}

// --- tool_distance ---

ToolShape sphere(double r) {
  return {ToolShape::Type::Sphere, r, 0};
}
ToolShape capsule(double r, double length) {
  return {ToolShape::Type::Capsule, r, length};
}

TEST(ToolDistance, SphereOutsideAndInside) {
  const ToolPose pose{Vec3(1, 2, 3), Vec3::UnitZ()};
  const ToolDistance out = tool_distance(sphere(0.01), pose, Vec3(1.02, 2, 3));
  EXPECT_NEAR(out.distance, 0.01, kTol);
  EXPECT_NEAR((out.normal - Vec3::UnitX()).norm(), 0, kTol);
  const ToolDistance in = tool_distance(sphere(0.01), pose, Vec3(1, 2 - 0.004, 3));
  EXPECT_NEAR(in.distance, -0.006, kTol);
  EXPECT_NEAR((in.normal + Vec3::UnitY()).norm(), 0, kTol);
  const Vec3 diagonal = Vec3(1, 2, 3) + 0.02 * Vec3(1, -2, 2) / 3;
  const ToolDistance d = tool_distance(sphere(0.01), pose, diagonal);
  EXPECT_NEAR(d.distance, 0.01, kTol);
  EXPECT_NEAR((d.normal - Vec3(1, -2, 2) / 3).norm(), 0, kTol);
}

TEST(ToolDistance, SphereCentreIsInsideByTheRadiusWithAUnitNormal) {
  const ToolDistance d = tool_distance(sphere(0.01), {Vec3(1, 2, 3), Vec3::UnitZ()}, Vec3(1, 2, 3));
  EXPECT_DOUBLE_EQ(d.distance, -0.01);
  EXPECT_NEAR(d.normal.norm(), 1, kTol);
}

TEST(ToolDistance, CapsuleAlongTheSide) {
  const ToolPose pose{Vec3::Zero(), Vec3::UnitZ()};
  const ToolShape s = capsule(0.01, 0.05);
  const ToolDistance out = tool_distance(s, pose, Vec3(0.02, 0, 0.025));
  EXPECT_NEAR(out.distance, 0.01, kTol);
  EXPECT_NEAR((out.normal - Vec3::UnitX()).norm(), 0, kTol);
  const ToolDistance in = tool_distance(s, pose, Vec3(0, -0.005, 0.03));
  EXPECT_NEAR(in.distance, -0.005, kTol);
  EXPECT_NEAR((in.normal + Vec3::UnitY()).norm(), 0, kTol);
}

TEST(ToolDistance, CapsuleOnTheCaps) {
  const ToolPose pose{Vec3::Zero(), Vec3::UnitZ()};
  const ToolShape s = capsule(0.01, 0.05);
  const ToolDistance tip = tool_distance(s, pose, Vec3(0, 0, -0.02));  // beyond the tip
  EXPECT_NEAR(tip.distance, 0.01, kTol);
  EXPECT_NEAR((tip.normal + Vec3::UnitZ()).norm(), 0, kTol);
  const ToolDistance end = tool_distance(s, pose, Vec3(0, 0, 0.053));  // inside the far cap
  EXPECT_NEAR(end.distance, -0.007, kTol);
  EXPECT_NEAR((end.normal - Vec3::UnitZ()).norm(), 0, kTol);
  // On the tip's hemisphere, off the axis: the distance is to the tip, not to the side's line.
  const ToolDistance cap = tool_distance(s, pose, Vec3(0.012, 0, -0.016));
  EXPECT_NEAR(cap.distance, 0.01, kTol);
  EXPECT_NEAR((cap.normal - Vec3(0.6, 0, -0.8)).norm(), 0, kTol);
}

TEST(ToolDistance, TiltedCapsuleMatchesTheSegmentDistance) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  const ToolPose pose{Vec3(0.01, -0.02, 0.03), Vec3(1, 1, 1).normalized()};
  const ToolShape s = capsule(0.004, 0.03);
  for (int i = 0; i < 200; ++i) {
    const Vec3 x(u(rng), u(rng), u(rng));
    // Brute force: the nearest of many points of the segment.
    double best = 1e300;
    for (int k = 0; k <= 30000; ++k) {
      const Vec3 p = pose.position + (s.length * k / 30000) * pose.axis;
      best = std::min(best, (x - p).norm());
    }
    const ToolDistance d = tool_distance(s, pose, x);
    EXPECT_NEAR(d.distance, best - s.radius, 1e-8);
    EXPECT_NEAR(d.normal.norm(), 1, kTol);
    // The closest surface point is at distance 0 from the surface.
    EXPECT_NEAR(tool_distance(s, pose, x - d.distance * d.normal).distance, 0, 1e-14);
  }
}

TEST(ToolDistance, PointOnTheSegmentGetsAUnitNormalPerpendicularToTheAxis) {
  const ToolShape s = capsule(0.01, 0.05);
  for (const Vec3& axis : {Vec3(Vec3::UnitZ()), Vec3(Vec3::UnitX()), Vec3(1, 1, 1).normalized(),
                           Vec3(0.3, -0.4, 0.5).normalized()}) {
    const ToolPose pose{Vec3(0.1, 0.2, 0.3), axis};
    for (double along : {0.0, 0.02, 0.05}) {
      const ToolDistance d = tool_distance(s, pose, pose.position + along * axis);
      EXPECT_NEAR(d.distance, -0.01, kTol);
      EXPECT_NEAR(d.normal.norm(), 1, kTol) << axis.transpose();
      EXPECT_NEAR(d.normal.dot(axis), 0, kTol) << axis.transpose();
    }
  }
}

// --- carry_point ---

TEST(ToolCarry, PureTranslation) {
  const ToolPose from{Vec3(0.1, 0.2, 0.3), Vec3(0, 0.6, 0.8)};
  const ToolPose to{Vec3(0.15, 0.1, 0.35), Vec3(0, 0.6, 0.8)};
  for (const Vec3& x : {Vec3(0, 0, 0), Vec3(0.1, 0.2, 0.3), Vec3(-1, 2, 0.5)}) {
    EXPECT_NEAR((carry_point(from, to, x) - (x + to.position - from.position)).norm(), 0, kTol);
  }
}

TEST(ToolCarry, QuarterTurnAboutTheTip) {
  // The axis turns from z to x about the tip: a rotation by 90 degrees about y.
  const Vec3 tip(1, 0, 0);
  const ToolPose from{tip, Vec3::UnitZ()}, to{tip, Vec3::UnitX()};
  EXPECT_NEAR((carry_point(from, to, tip) - tip).norm(), 0, kTol);
  EXPECT_NEAR(
      (carry_point(from, to, tip + 0.5 * Vec3::UnitZ()) - (tip + 0.5 * Vec3::UnitX())).norm(), 0,
      kTol);
  EXPECT_NEAR((carry_point(from, to, tip + Vec3::UnitX()) - (tip - Vec3::UnitZ())).norm(), 0, kTol);
  EXPECT_NEAR((carry_point(from, to, tip + Vec3::UnitY()) - (tip + Vec3::UnitY())).norm(), 0, kTol);
  // With a translation of the tip as well.
  const ToolPose moved{Vec3(2, 0, 0), Vec3::UnitX()};
  EXPECT_NEAR((carry_point(from, moved, tip + 0.5 * Vec3::UnitZ()) - Vec3(2.5, 0, 0)).norm(), 0,
              kTol);
}

TEST(ToolCarry, IsRigidAndCarriesTheShaft) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 30; ++trial) {
    const ToolPose from{Vec3(u(rng), u(rng), u(rng)), random_unit(rng)};
    const ToolPose to{Vec3(u(rng), u(rng), u(rng)), random_unit(rng)};
    const Vec3 x(u(rng), u(rng), u(rng)), y(u(rng), u(rng), u(rng));
    const Vec3 cx = carry_point(from, to, x), cy = carry_point(from, to, y);
    EXPECT_NEAR((cx - cy).norm(), (x - y).norm(), 1e-12);
    EXPECT_NEAR((cx - to.position).norm(), (x - from.position).norm(), 1e-12);
    const Vec3 shaft = carry_point(from, to, from.position + 0.3 * from.axis);
    EXPECT_NEAR((shaft - (to.position + 0.3 * to.axis)).norm(), 0, 1e-12);
  }
}

TEST(ToolCarry, HalfTurnKeepsDistances) {
  const ToolPose from{Vec3::Zero(), Vec3::UnitZ()}, to{Vec3::Zero(), -Vec3::UnitZ()};
  const Vec3 x(0.3, -0.2, 0.5);
  const Vec3 c = carry_point(from, to, x);
  EXPECT_NEAR(c.norm(), x.norm(), kTol);
  EXPECT_NEAR(c.z(), -0.5, kTol);  // the shaft's coordinate flips with the axis
}

// --- bounds ---

TEST(ToolBounds, SphereIsCentrePlusMinusRadius) {
  const Bounds b = tool_bounds(sphere(0.01), {Vec3(1, 2, 3), Vec3::UnitX()});
  EXPECT_NEAR((b.min - Vec3(0.99, 1.99, 2.99)).norm(), 0, kTol);
  EXPECT_NEAR((b.max - Vec3(1.01, 2.01, 3.01)).norm(), 0, kTol);
  EXPECT_FALSE(b.empty());
}

TEST(ToolBounds, CapsuleCoversTheSegmentGrownByTheRadius) {
  const Bounds b = tool_bounds(capsule(0.01, 0.05), {Vec3(0, 0, 0), -Vec3::UnitX()});
  EXPECT_NEAR((b.min - Vec3(-0.06, -0.01, -0.01)).norm(), 0, kTol);
  EXPECT_NEAR((b.max - Vec3(0.01, 0.01, 0.01)).norm(), 0, kTol);
}

TEST(ToolBounds, ContainEverySurfacePointAndAreTight) {
  std::mt19937 rng(9);
  const ToolShape s = capsule(0.004, 0.03);
  const ToolPose pose{Vec3(0.01, 0.02, -0.03), Vec3(0.2, -0.5, 0.7).normalized()};
  const Bounds b = tool_bounds(s, pose);
  // Random surface points, and the six extreme points of each end's sphere.
  std::vector<Vec3> points;
  for (int i = 0; i < 20000; ++i) {
    const double along = s.length * (i % 101) / 100.0;
    points.push_back(pose.position + along * pose.axis + s.radius * random_unit(rng));
  }
  for (double along : {0.0, s.length}) {
    for (int a = 0; a < 3; ++a) {
      for (double sign : {-1.0, 1.0}) {
        points.push_back(pose.position + along * pose.axis + sign * s.radius * Vec3::Unit(a));
      }
    }
  }
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Vec3& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
    EXPECT_TRUE((p.array() >= b.min.array() - 1e-15).all() &&
                (p.array() <= b.max.array() + 1e-15).all());
  }
  EXPECT_NEAR((lo - b.min).cwiseAbs().maxCoeff(), 0, 1e-15);
  EXPECT_NEAR((hi - b.max).cwiseAbs().maxCoeff(), 0, 1e-15);
}

TEST(ToolBounds, EmptyExtendAndGrow) {
  Bounds b;
  EXPECT_TRUE(b.empty());
  b.extend(tool_bounds(sphere(1), {Vec3(0, 0, 0), Vec3::UnitZ()}));
  b.extend(tool_bounds(sphere(1), {Vec3(5, 0, 0), Vec3::UnitZ()}));
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.min, Vec3(-1, -1, -1));
  EXPECT_EQ(b.max, Vec3(6, 1, 1));
  b.grow(0.5);
  EXPECT_EQ(b.min, Vec3(-1.5, -1.5, -1.5));
  EXPECT_EQ(b.max, Vec3(6.5, 1.5, 1.5));
}

}  // namespace
}  // namespace phyxel
