// Sphere and ellipsoid sampling: volume, symmetric lattice, surface flags and normals.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <tuple>

#include "engine/sampling/phyxel_set.h"
#include "sampling_helpers.h"

namespace phyxel::test {
namespace {

using Site = std::tuple<long, long, long>;

// Lattice coordinates of the phyxels relative to `center`.
std::set<Site> sites(const PhyxelSet& set, const Vec3& center, double s) {
  std::set<Site> out;
  for (const Vec3& p : set.rest) {
    const Vec3 q = (p - center) / s;
    EXPECT_NEAR((q - q.array().round().matrix()).norm(), 0, 1e-6);
    out.emplace(std::lround(q.x()), std::lround(q.y()), std::lround(q.z()));
  }
  return out;
}

// Every site's mirror images under the sign flips of each axis are sites too.
void expect_mirror_symmetric(const std::set<Site>& s) {
  for (const auto& [i, j, k] : s)
    for (const Site& m : {Site{-i, j, k}, Site{i, -j, k}, Site{i, j, -k}})
      ASSERT_TRUE(s.count(m)) << i << " " << j << " " << k;
}

double sphere_volume(const Vec3& r) {
  return 4.0 / 3.0 * std::numbers::pi * r.prod();
}

TEST(SphereSampling, CentredSymmetricLatticeWithTheCentreAndPoles) {
  const Vec3 c(0.0123, -0.0456, 0.789);
  const double r = 0.02, s = 0.001;
  const PhyxelSet set = sample_scene(scene_of({object("ball", sphere(c, r), s)}));
  const std::set<Site> s_sites = sites(set, c, s);
  EXPECT_EQ(s_sites.size(), set.size());
  EXPECT_TRUE(s_sites.count({0, 0, 0}));
  // Points exactly on the surface belong to the object.
  for (const Site& pole : {Site{20, 0, 0}, Site{-20, 0, 0}, Site{0, 0, 20}, Site{0, -20, 0}})
    EXPECT_TRUE(s_sites.count(pole));
  expect_mirror_symmetric(s_sites);
  for (const auto& [i, j, k] : s_sites) ASSERT_TRUE(s_sites.count({j, k, i}));
  // The phyxels are exactly the sites within the radius.
  size_t expected = 0;
  for (long i = -20; i <= 20; ++i)
    for (long j = -20; j <= 20; ++j)
      for (long k = -20; k <= 20; ++k) expected += i * i + j * j + k * k <= 400;
  EXPECT_EQ(set.size(), expected);
}

TEST(SphereSampling, VolumesAddUpToTheBallVolume) {
  // Each phyxel also gets the inside parts of the cells of the non-phyxel sites next to it:
  // with its own cell alone the total would be 3.8 % short at r/s = 10 and 1.9 % at 20.
  for (const double cells : {10.0, 20.0}) {
    const double r = 0.05, s = r / cells;
    const PhyxelSet set = sample_scene(scene_of({object("ball", sphere(Vec3::Zero(), r), s)}));
    const double exact = sphere_volume(Vec3::Constant(r));
    EXPECT_NEAR(total_volume(set), exact, 0.002 * exact) << "r/s = " << cells;
    for (double v : set.volume) {
      EXPECT_GT(v, 0);
      EXPECT_LT(v, 2 * s * s * s);
    }
  }
}

TEST(SphereSampling, SurfacePhyxelsHaveOutwardRadialNormals) {
  const double r = 0.02, s = 0.001;
  const Vec3 c(0.1, 0.2, 0.3);
  const PhyxelSet set = sample_scene(scene_of({object("ball", sphere(c, r), s)}));
  size_t surface = 0;
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 d = set.rest[i] - c;
    if (set.flags[i] & kSurface) {
      ++surface;
      EXPECT_GT(d.norm(), r - std::sqrt(3.0) * s);
      EXPECT_GT(set.normal[i].dot(d), 0);
      EXPECT_NEAR((set.normal[i] - d.normalized()).norm(), 0, 1e-12);
      EXPECT_DOUBLE_EQ(set.splat_radius[i], 0.8 * s);
    } else {
      // All six face neighbours are inside, so the largest coordinate can grow by s.
      EXPECT_LE(d.norm(), r - s / std::sqrt(3.0) + 1e-12);
      EXPECT_EQ(set.normal[i], Vec3::Zero());
      EXPECT_EQ(set.splat_radius[i], 0);
    }
  }
  // Each lattice line through the ball has a surface phyxel at both ends: 2 pi r^2 / s^2 per
  // axis; the three axes' sets overlap.
  const double per_axis = 2 * std::numbers::pi * (r / s) * (r / s);
  EXPECT_GT(double(surface), per_axis);
  EXPECT_LT(double(surface), 3 * per_axis);
}

TEST(SphereSampling, ASphereSmallerThanTheSpacingIsItsCentre) {
  // The geometry of a lone phyxel; a run refuses it (tests/sampling/small_body_test.cpp).
  const PhyxelSet set = sample_scene(
      scene_of({object("dot", sphere(Vec3(1, 2, 3), 0.0003), 0.001)}), SamplingOptions{false});
  ASSERT_EQ(set.size(), 1u);
  EXPECT_EQ(set.rest[0], Vec3(1, 2, 3));
  // The eight sub-cell centres at (+-1/8, +-1/8, +-1/8) s are within 0.3 s.
  EXPECT_NEAR(set.volume[0], 1e-9 / 8, 1e-24);
  EXPECT_NEAR(set.normal[0].norm(), 1, 1e-12);
}

TEST(EllipsoidSampling, SymmetricVolumeAndGradientNormals) {
  const Vec3 c(-0.3, 0.01, 0.5), radii(0.05, 0.03, 0.02);
  const double s = 0.002;
  const PhyxelSet set = sample_scene(scene_of({object("egg", ellipsoid(c, radii), s)}));
  const std::set<Site> e_sites = sites(set, c, s);
  EXPECT_TRUE(e_sites.count({0, 0, 0}));
  EXPECT_TRUE(e_sites.count({25, 0, 0}));
  EXPECT_TRUE(e_sites.count({0, -15, 0}));
  EXPECT_TRUE(e_sites.count({0, 0, 10}));
  EXPECT_FALSE(e_sites.count({0, 0, 11}));
  expect_mirror_symmetric(e_sites);
  const double exact = sphere_volume(radii);
  EXPECT_NEAR(total_volume(set), exact, 0.002 * exact);
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 d = set.rest[i] - c;
    EXPECT_LE(d.cwiseQuotient(radii).squaredNorm(), 1 + 1e-9);
    if (!(set.flags[i] & kSurface)) continue;
    const Vec3 gradient = d.cwiseQuotient(radii.cwiseProduct(radii)).normalized();
    EXPECT_NEAR((set.normal[i] - gradient).norm(), 0, 1e-12);
    EXPECT_GT(set.normal[i].dot(d), 0);
  }
}

}  // namespace
}  // namespace phyxel::test
