// The fracture surface's noise (engine/surgery/fracture_surface.h): the paper's noise plane
// with the ring falloff of eq 27, the mapping of eqs 28-29 and the overlay of eq 30, its height
// field, the seeded Perlin noise, and the renderer's displacement along surfel normals.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "engine/surgery/fracture_surface.h"

namespace phyxel {
namespace {

NoiseParams params(uint64_t seed = 7) {
  NoiseParams p;
  p.seed = seed;
  p.frequency = 0.15;  // per cell: a lattice cell every ~7 grid cells
  p.amplitude = 2.0;
  p.octaves = 4;
  p.persistence = 0.5;
  return p;
}

TEST(FractureSurface, RingFalloffIsEq27BetweenHalfAndNineTenthsOfR) {
  const double r = 40;
  for (const double d : {0.0, 5.0, 19.9, 20.0}) EXPECT_EQ(ring_falloff(d, r), 1.0) << d;
  EXPECT_NEAR(ring_falloff(24, r), 0.75, 1e-12);  // 0.6 R
  EXPECT_NEAR(ring_falloff(28, r), 0.50, 1e-12);  // 0.7 R
  EXPECT_NEAR(ring_falloff(32, r), 0.25, 1e-12);  // 0.8 R
  EXPECT_NEAR(ring_falloff(35, r), 1 - (35 - 20.0) / (36 - 20.0), 1e-12);
  for (const double d : {36.0, 36.001, 40.0, 100.0}) EXPECT_EQ(ring_falloff(d, r), 0.0) << d;
}

TEST(FractureSurface, NoisePlaneIsZeroBeyondNineTenthsOfRAndRampsByEq27) {
  const NoiseParams p = params();
  const int rows = 64, cols = 64;
  const double radius = 32;  // the plane spans the fracture's diameter: R = cols / 2 cells
  const NoisePlane plane = make_noise_plane(p, rows, cols, radius);
  ASSERT_EQ(plane.value.size(), size_t(65 * 65));
  int outside = 0, ring = 0, inside = 0, nonzero_inside = 0;
  for (int r = 0; r <= rows; ++r)
    for (int c = 0; c <= cols; ++c) {
      const double d = std::hypot(c - 32.0, r - 32.0);
      const double f = fbm2(p, c, r);
      if (d > 0.9 * radius) {
        ++outside;
        EXPECT_EQ(plane.at(r, c), 0.0) << "(" << r << ", " << c << ") d " << d;
      } else if (d >= 0.5 * radius) {
        ++ring;
        const double ramp = 1 - (d - 16) / (28.8 - 16);
        EXPECT_NEAR(plane.at(r, c), f * ramp, 1e-12) << d;
      } else {
        ++inside;
        EXPECT_EQ(plane.at(r, c), f) << "untouched inside 0.5 R";
        nonzero_inside += f != 0;
      }
    }
  EXPECT_GT(outside, 1000);
  EXPECT_GT(ring, 1000);
  EXPECT_GT(nonzero_inside, inside / 2);
}

TEST(FractureSurface, Eqs28And29MapTheSurfaceBoundsOntoThePlaneBounds) {
  const Bounds2 surface{-0.02, 0.03, 0.1, 0.14};
  const Bounds2 plane{0, 64, 0, 32};
  const Eigen::Vector2d lo = map_to_plane(-0.02, 0.1, surface, plane);
  const Eigen::Vector2d hi = map_to_plane(0.03, 0.14, surface, plane);
  const Eigen::Vector2d mid = map_to_plane(0.005, 0.12, surface, plane);
  EXPECT_NEAR(lo.x(), 0, 1e-12);
  EXPECT_NEAR(lo.y(), 0, 1e-12);
  EXPECT_NEAR(hi.x(), 64, 1e-12);
  EXPECT_NEAR(hi.y(), 32, 1e-12);
  EXPECT_NEAR(mid.x(), 32, 1e-12);
  EXPECT_NEAR(mid.y(), 16, 1e-12);
  // min^p + (x - min) (max^p - min^p) / (max - min) at a quarter.
  EXPECT_NEAR(map_to_plane(-0.0075, 0.11, surface, plane).x(), 16, 1e-12);
  EXPECT_NEAR(map_to_plane(-0.0075, 0.11, surface, plane).y(), 8, 1e-12);
  // A flat extent maps to the plane's middle.
  EXPECT_NEAR(map_to_plane(1, 1, Bounds2{1, 1, 1, 1}, plane).x(), 32, 1e-12);
}

TEST(FractureSurface, Eq30AddsThePlaneValueAtTheMappedPointToZ) {
  // A plane of known, bilinear values f(X, Y) = X - 3 Y: its bilinear samples are exact.
  NoisePlane plane;
  plane.rows = 4;
  plane.cols = 8;
  for (int r = 0; r <= 4; ++r)
    for (int c = 0; c <= 8; ++c) plane.value.push_back(c - 3.0 * r);
  const std::vector<Vec3> points = {
      {1.0, 2.0, 0.5}, {3.0, 2.0, 0.25}, {1.0, 4.0, -1.0}, {2.5, 3.0, 0.0}, {1.5, 2.5, 2.0}};
  const std::vector<Vec3> out = disturb_fracture_points(points, plane);
  ASSERT_EQ(out.size(), points.size());
  for (size_t k = 0; k < points.size(); ++k) {
    const double big_x = (points[k].x() - 1.0) * 8 / 2.0, big_y = (points[k].y() - 2.0) * 4 / 2.0;
    EXPECT_EQ(out[k].x(), points[k].x());
    EXPECT_EQ(out[k].y(), points[k].y());
    EXPECT_NEAR(out[k].z(), points[k].z() + big_x - 3 * big_y, 1e-12) << k;
  }
}

TEST(FractureSurface, HeightFieldTakesTheLargestZPerCellAtItsLowerLeftCorner) {
  // Points over [0, 3] x [0, 2]: 3 x 2 cells of 1 x 1.
  const std::vector<Vec3> points = {{0.0, 0.0, -1.0}, {0.2, 0.3, 0.5}, {0.7, 0.9, 0.25},
                                    {1.5, 0.5, 2.0},  {2.9, 1.9, 1.0}, {3.0, 2.0, 1.5},
                                    {0.5, 1.5, 0.75}};
  const HeightField field = make_height_field(points, 3, 2);
  EXPECT_DOUBLE_EQ(field.cell_x, 1.0);
  EXPECT_DOUBLE_EQ(field.cell_y, 1.0);
  EXPECT_EQ(field.at(0, 0), 0.5);   // max of -1, 0.5, 0.25
  EXPECT_EQ(field.at(1, 0), 2.0);   // one point
  EXPECT_EQ(field.at(2, 0), -1.0);  // empty: the smallest z of all points
  EXPECT_EQ(field.at(0, 1), 0.75);
  EXPECT_EQ(field.at(1, 1), -1.0);
  EXPECT_EQ(field.at(2, 1), 1.5);  // the upper bound falls in the last cell
  EXPECT_EQ(field.corner(1, 1), Vec3(1, 1, -1));
  const auto triangles = field.triangles();
  ASSERT_EQ(triangles.size(), 4u);  // (3 - 1) x (2 - 1) squares, two triangles each
  for (const auto& t : triangles) {
    const Vec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
    EXPECT_GT(n.z(), 0) << "counter-clockwise from +z";
  }
  // The first square: A = (0, 1), B = (1, 1), C = (1, 0), D = (0, 0).
  EXPECT_EQ(triangles[0][0], Vec3(0, 1, 0.75));
  EXPECT_EQ(triangles[0][1], Vec3(0, 0, 0.5));
  EXPECT_EQ(triangles[0][2], Vec3(1, 1, -1));
  EXPECT_EQ(triangles[1][2], Vec3(1, 0, 2));
}

TEST(FractureSurface, NoiseIsDeterministicPerSeedAndDiffersBetweenSeeds) {
  const PerlinNoise a(42), b(42), c(43);
  EXPECT_EQ(a.perm(), b.perm());
  EXPECT_NE(a.perm(), c.perm());
  // The permutation is integer arithmetic only (SplitMix64, Fisher-Yates): pinned here, so a
  // change of the generator shows (the values are those of an independent Python replica).
  const std::array<uint8_t, 8> head = {a.perm()[0], a.perm()[1], a.perm()[2], a.perm()[3],
                                       a.perm()[4], a.perm()[5], a.perm()[6], a.perm()[7]};
  EXPECT_EQ(head, (std::array<uint8_t, 8>{203, 217, 124, 199, 53, 101, 223, 240}));
  int differ = 0;
  for (int k = 0; k < 200; ++k) {
    const Vec3 x(0.37 * k, 0.11 * k - 3, 0.05 * k * k);
    EXPECT_EQ(a.noise3(x), b.noise3(x));
    EXPECT_EQ(a.noise2(x.x(), x.y()), b.noise2(x.x(), x.y()));
    EXPECT_EQ(fbm2(params(5), x.x(), x.y()), fbm2(params(5), x.x(), x.y()));
    differ += std::abs(a.noise3(x) - c.noise3(x)) > 1e-3;
  }
  EXPECT_GT(differ, 150);
  EXPECT_NE(fbm2(params(5), 3.3, 4.4), fbm2(params(6), 3.3, 4.4));
}

TEST(FractureSurface, NoiseIsBoundedByItsAmplitudeAndReachesMuchOfIt) {
  for (const int octaves : {1, 3, 6}) {
    NoiseParams p = params(11);
    p.octaves = octaves;
    p.amplitude = 0.3;
    p.frequency = 0.731;
    double max2 = 0, max3 = 0;
    for (int k = 0; k < 40000; ++k) {
      const double x = 0.0173 * k - 300, y = std::fmod(0.619 * k, 97.0) - 40;
      const Vec3 q(x, y, std::fmod(0.377 * k, 31.0));
      max2 = std::max(max2, std::abs(fbm2(p, x, y)));
      max3 = std::max(max3, std::abs(fbm3(p, q)));
    }
    EXPECT_LE(max2, p.amplitude) << octaves << " octaves";
    EXPECT_LE(max3, p.amplitude) << octaves << " octaves";
    EXPECT_GT(max2, 0.3 * p.amplitude) << "2-D noise of " << octaves << " octaves is not flat";
    EXPECT_GT(max3, 0.3 * p.amplitude) << "3-D noise of " << octaves << " octaves is not flat";
  }
}

TEST(FractureSurface, Fbm3GradientIsTheDerivativeOfItsValue) {
  const NoiseParams p = params(3);
  const double e = 1e-6;
  for (int k = 0; k < 50; ++k) {
    const Vec3 x(0.71 * k + 0.1, 1.3 - 0.29 * k, 0.17 * k * k);
    Vec3 g;
    fbm3(p, x, &g);
    for (int a = 0; a < 3; ++a) {
      const Vec3 d = e * Vec3::Unit(a);
      const double fd = (fbm3(p, x + d) - fbm3(p, x - d)) / (2 * e);
      EXPECT_NEAR(g(a), fd, 1e-5) << "point " << k << " axis " << a;
    }
  }
}

TEST(FractureSurface, NormalDisplacementOnASphereIsBoundedAndFallsOffFromTheAxis) {
  // A suction crater: a sphere of R = 1 cm around c, the tool along +z.
  NoiseParams p = params(9);
  p.amplitude = 0.0006;  // m
  p.frequency = 400;     // per m: a lattice cell every 2.5 mm
  p.octaves = 3;
  const FractureRegion region{Vec3(0.01, -0.02, 0.03), 0.01, Vec3(0, 0, 2)};
  int full = 0, ring = 0, zero = 0, tilted = 0;
  for (int a = 0; a < 60; ++a)
    for (int b = 0; b < 30; ++b) {
      const double phi = a * 2 * M_PI / 60, theta = (b + 0.5) * M_PI / 30;
      const Vec3 n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                   std::cos(theta));
      const Vec3 x = region.centre + region.radius * n;
      const RoughSurfel s = rough_surfel(p, region, x, n);
      const double d = region.radius * std::sin(theta);  // from the axis
      EXPECT_LE(std::abs(s.displacement), p.amplitude);
      EXPECT_NEAR(s.normal.norm(), 1, 1e-12);
      EXPECT_GT(s.normal.dot(n), 0.5) << "the tilt stays moderate";
      EXPECT_NEAR(s.falloff, ring_falloff(d, region.radius), 1e-12);
      if (d >= 0.9 * region.radius) {
        ++zero;
        EXPECT_EQ(s.displacement, 0.0);
        EXPECT_EQ(s.normal, n);
      } else if (d <= 0.5 * region.radius) {
        ++full;
        EXPECT_EQ(s.displacement, fbm3(p, x));
      } else {
        ++ring;
        EXPECT_NEAR(s.displacement, fbm3(p, x) * ring_falloff(d, region.radius), 1e-15);
      }
      tilted += (s.normal - n).norm() > 0.02;
    }
  EXPECT_GT(full, 200);
  EXPECT_GT(ring, 200);
  EXPECT_GT(zero, 200);
  EXPECT_GT(tilted, 200) << "the normals show the roughness";
  // No region (a torn face): the displacement is the noise itself.
  const Vec3 x(0.001, 0.002, 0.003);
  EXPECT_EQ(rough_surfel(p, FractureRegion{}, x, Vec3::UnitZ()).displacement, fbm3(p, x));
}

TEST(FractureSurface, PerturbedNormalIsTheDisplacedSurfacesNormal) {
  // A plane z = 0 with normal +z, displaced to z = h(x, y): its normal is (-h_x, -h_y, 1).
  NoiseParams p = params(21);
  p.amplitude = 0.0005;
  p.frequency = 300;
  const FractureRegion region{Vec3::Zero(), 0.02, Vec3::UnitZ()};
  const double e = 1e-7;
  for (int k = 0; k < 40; ++k) {
    const Vec3 x(0.0003 * k - 0.0061, 0.00041 * k - 0.0083, 0);  // off the ring's kinks
    auto h = [&](const Vec3& q) { return rough_surfel(p, region, q, Vec3::UnitZ()).displacement; };
    const double hx = (h(x + Vec3(e, 0, 0)) - h(x - Vec3(e, 0, 0))) / (2 * e);
    const double hy = (h(x + Vec3(0, e, 0)) - h(x - Vec3(0, e, 0))) / (2 * e);
    const Vec3 want = Vec3(-hx, -hy, 1).normalized();
    EXPECT_LT((rough_surfel(p, region, x, Vec3::UnitZ()).normal - want).norm(), 1e-5) << k;
  }
}

}  // namespace
}  // namespace phyxel
