// CutFaces (engine/surgery/cut_faces.h): the faces a cut leaves per phyxel, from severed pairs.
// A plane through a lattice gives both sides the plane's normal (out of each piece), at any
// orientation including vertical planes; a curved cut gives the local normal; one or two
// crossing points (or collinear ones) fall back to the mean direction.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "engine/surgery/cut_faces.h"

namespace phyxel {
namespace {

// A lattice of n^3 points of spacing s (only the rest positions: all CutFaces reads).
PhyxelSet lattice(int nx, int ny, int nz, double s) {
  PhyxelSet set;
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) set.rest.emplace_back(x * s, y * s, z * s);
  return set;
}

// Every pair (i < j) closer than h whose segment the level set `f` (f < 0 on one side)
// changes sign along, severed where f crosses 0 (by bisection of f along the segment).
std::vector<SeveredPair> sever_where(const PhyxelSet& set, double h,
                                     const std::function<double(const Vec3&)>& f) {
  std::vector<SeveredPair> pairs;
  for (uint32_t i = 0; i < set.size(); ++i)
    for (uint32_t j = i + 1; j < set.size(); ++j) {
      const Vec3 &a = set.rest[i], &b = set.rest[j];
      if ((b - a).norm() >= h || (f(a) < 0) == (f(b) < 0)) continue;
      double lo = 0, hi = 1;
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        ((f(a + mid * (b - a)) < 0) == (f(a) < 0) ? lo : hi) = mid;
      }
      pairs.push_back({i, j, static_cast<float>(0.5 * (lo + hi))});
    }
  return pairs;
}

// The pair's t is a float: the crossing points lie on the surface to ~1e-7 of the spacing.
void expect_plane_normals(const Vec3& normal, const Vec3& through) {
  const double s = 0.002, h = 2 * s;
  const PhyxelSet set = lattice(8, 8, 8, s);
  const Vec3 n = normal.normalized();
  auto side = [&](const Vec3& x) { return n.dot(x - through); };
  CutFaces faces;
  faces.add(set, sever_where(set, h, side));
  ASSERT_GT(faces.size(), 50u);
  size_t fitted = 0;
  for (uint32_t k = 0; k < set.size(); ++k) {
    const CutFace* face = faces.face(k);
    if (face == nullptr) continue;
    // Out of the phyxel's own piece: toward the other side of the plane.
    const Vec3 expected = side(set.rest[k]) < 0 ? n : Vec3(-n);
    if (face->fitted) {
      ++fitted;
      EXPECT_LT((face->normal - expected).norm(), 1e-6)
          << "phyxel " << k << " normal " << face->normal.transpose();
      EXPECT_NEAR(face->offset, std::abs(side(set.rest[k])), 1e-6 * s);
    } else {
      EXPECT_GT(face->normal.dot(expected), 0.0) << "phyxel " << k;
    }
  }
  // Phyxels up to h from the plane see only the pairs that reach across: the farthest have
  // one or two crossing points (and the fallback).
  EXPECT_GE(2 * fitted, faces.size()) << "most faces have a plane of points";
}

TEST(CutFaces, PlaneCutGivesThePlaneNormalOnBothSides) {
  expect_plane_normals(Vec3(1, 2, 3), Vec3(0.0071, 0.0069, 0.0073));
  expect_plane_normals(Vec3(0, 0, 1), Vec3(0.007, 0.007, 0.0071));
}

TEST(CutFaces, VerticalPlanesWork) {
  // Planes containing the z axis direction: z = a0 x + a1 y + a2 (eqs 18-20) cannot fit them.
  expect_plane_normals(Vec3(1, 0, 0), Vec3(0.0071, 0.007, 0.007));
  expect_plane_normals(Vec3(1, -0.4, 0), Vec3(0.0071, 0.007, 0.007));
}

TEST(CutFaces, CurvedCutGivesTheLocalNormal) {
  const double s = 0.002, h = 2 * s, radius = 8 * s;
  const Vec3 axis_at(0.0231, 0.0229, 0);  // the cylinder's axis, along z, inside the lattice
  const PhyxelSet set = lattice(24, 24, 4, s);
  auto f = [&](const Vec3& x) { return (x - axis_at).head<2>().norm() - radius; };
  CutFaces faces;
  faces.add(set, sever_where(set, h, f));
  ASSERT_GT(faces.size(), 300u);
  size_t fitted = 0;
  double worst = 0, mean = 0;
  for (uint32_t k = 0; k < set.size(); ++k) {
    const CutFace* face = faces.face(k);
    if (face == nullptr) continue;
    // The cylinder's normal where the face is, out of the phyxel's piece: outward from the
    // inside, inward from the outside.
    Vec3 radial = face->centroid - axis_at;
    radial.z() = 0;
    const Vec3 expected = (f(set.rest[k]) < 0 ? 1.0 : -1.0) * radial.normalized();
    if (face->fitted) {
      ++fitted;
      const double angle = std::acos(std::min(1.0, face->normal.dot(expected)));
      worst = std::max(worst, angle);
      mean += angle;
    } else {
      EXPECT_GT(face->normal.dot(expected), 0.5) << "phyxel " << k;
    }
  }
  EXPECT_GE(2 * fitted, faces.size());
  mean /= double(std::max<size_t>(fitted, 1));
  // The fit is a plane through points on an arc of radius 8 spacings that span up to +-h/R =
  // +-0.25 rad of it; where they spread unevenly around the centroid the plane tilts by a small
  // part of that (0.042 rad at worst here, 0.01 on average).
  EXPECT_LT(worst, 0.06) << "radians";
  EXPECT_LT(mean, 0.02) << "radians";
  std::printf(
      "curved cut: %zu faces, %zu fitted, angle to the local normal: worst %.4f rad, "
      "mean %.4f rad\n",
      faces.size(), fitted, worst, mean);
}

TEST(CutFaces, OneOrTwoOrCollinearPointsUseTheMeanDirection) {
  PhyxelSet set;
  set.rest = {Vec3(0, 0, 0), Vec3(0.002, 0, 0), Vec3(0, 0.002, 0), Vec3(0.004, 0, 0),
              Vec3(0.006, 0, 0)};
  CutFaces one;
  one.add(set, {{0, 1, 0.25f}});
  ASSERT_NE(one.face(0), nullptr);
  EXPECT_FALSE(one.face(0)->fitted);
  EXPECT_LT((one.face(0)->normal - Vec3(1, 0, 0)).norm(), 1e-12);
  EXPECT_LT((one.face(1)->normal - Vec3(-1, 0, 0)).norm(), 1e-12) << "j's face points to i";
  EXPECT_NEAR(one.face(0)->offset, 0.0005, 1e-12);
  EXPECT_NEAR(one.face(1)->offset, 0.0015, 1e-9);

  CutFaces two;
  two.add(set, {{0, 1, 0.5f}, {0, 2, 0.5f}});
  EXPECT_FALSE(two.face(0)->fitted);
  EXPECT_LT((two.face(0)->normal - Vec3(1, 1, 0).normalized()).norm(), 1e-12);

  // Three crossing points on the x axis: collinear, no plane.
  CutFaces line;
  line.add(set, {{0, 1, 0.5f}, {0, 3, 0.5f}, {0, 4, 0.5f}});
  EXPECT_FALSE(line.face(0)->fitted);
  EXPECT_LT((line.face(0)->normal - Vec3(1, 0, 0)).norm(), 1e-12);
}

TEST(CutFaces, ReportsTheChangedPhyxelsOnce) {
  PhyxelSet set = lattice(3, 3, 1, 0.002);
  CutFaces faces;
  EXPECT_TRUE(faces.take_changed().empty());
  faces.add(set, {{0, 1, 0.5f}, {0, 3, 0.5f}});
  EXPECT_EQ(faces.take_changed(), (std::vector<uint32_t>{0, 1, 3}));
  EXPECT_TRUE(faces.take_changed().empty());
  faces.add(set, {{3, 4, 0.5f}});
  faces.add(set, {{1, 4, 0.5f}});
  EXPECT_EQ(faces.take_changed(), (std::vector<uint32_t>{1, 3, 4}));
  EXPECT_EQ(faces.face(0)->points.size(), 2u);
  EXPECT_EQ(faces.face(4)->points.size(), 2u);
  EXPECT_THROW(faces.add(set, {{0, 99, 0.5f}}), std::invalid_argument);
}

TEST(CutFaces, AFaceWithATornPairIsTorn) {
  PhyxelSet set = lattice(3, 3, 1, 0.002);
  CutFaces faces;
  faces.add(set, {{0, 1, 0.5f, false}, {3, 4, 0.5f, true}});
  EXPECT_FALSE(faces.face(0)->torn);
  EXPECT_FALSE(faces.face(1)->torn);
  EXPECT_TRUE(faces.face(3)->torn);
  EXPECT_TRUE(faces.face(4)->torn);
  // A cut face that a later tear reaches becomes torn, and stays so after a later clean cut.
  faces.add(set, {{1, 4, 0.5f, false}});
  EXPECT_FALSE(faces.face(1)->torn);
  faces.add(set, {{0, 3, 0.5f, true}});
  EXPECT_TRUE(faces.face(0)->torn);
  faces.add(set, {{0, 4, 0.5f, false}});
  EXPECT_TRUE(faces.face(0)->torn);
  EXPECT_TRUE(faces.face(4)->torn);
}

}  // namespace
}  // namespace phyxel
