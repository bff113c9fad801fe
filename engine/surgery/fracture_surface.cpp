#include "engine/surgery/fracture_surface.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace phyxel {
namespace {

// SplitMix64 (Steele, Lea, Flood 2014): a fixed integer sequence from the seed.
uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

constexpr double kHalfSqrt2 = 0.70710678118654752440;
constexpr double kHalfSqrt3 = 0.86602540378443864676;

// 2-D: eight unit directions (axes and diagonals).
constexpr double kGrad2[8][2] = {{1, 0},
                                 {-1, 0},
                                 {0, 1},
                                 {0, -1},
                                 {kHalfSqrt2, kHalfSqrt2},
                                 {-kHalfSqrt2, kHalfSqrt2},
                                 {kHalfSqrt2, -kHalfSqrt2},
                                 {-kHalfSqrt2, -kHalfSqrt2}};

// 3-D: Perlin's twelve cube-edge directions (2002), made unit, plus four repeated so a hash
// picks one by its low four bits.
constexpr double kGrad3[16][3] = {
    {1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1}, {1, 0, -1}, {-1, 0, -1},
    {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}, {1, 1, 0}, {-1, 1, 0}, {0, -1, 1}, {0, -1, -1}};

// Perlin's quintic fade and its derivative.
double fade(double t) {
  return t * t * t * (t * (t * 6 - 15) + 10);
}
double fade_slope(double t) {
  return 30 * t * t * (t * (t - 2) + 1);
}

double lerp(double a, double b, double t) {
  return a + t * (b - a);
}

void check_params(const NoiseParams& p) {
  if (p.octaves < 1 || !(p.frequency > 0) || !(p.amplitude >= 0) || !(p.persistence > 0)) {
    throw std::invalid_argument(
        "NoiseParams: octaves >= 1, frequency > 0, amplitude >= 0 and persistence > 0 needed");
  }
}

}  // namespace

PerlinNoise::PerlinNoise(uint64_t seed) {
  for (int k = 0; k < 256; ++k) perm_[size_t(k)] = static_cast<uint8_t>(k);
  uint64_t state = seed;
  for (size_t k = 255; k > 0; --k) {
    const size_t pick = static_cast<size_t>(splitmix64(state) % (k + 1));
    std::swap(perm_[k], perm_[pick]);
  }
}

double PerlinNoise::noise2(double x, double y) const {
  const double fx = std::floor(x), fy = std::floor(y);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  const double dx = x - fx, dy = y - fy;
  auto corner = [&](int cx, int cy) {
    const double* g = kGrad2[hash(ix + cx + hash(iy + cy)) & 7u];
    return g[0] * (dx - cx) + g[1] * (dy - cy);
  };
  const double u = fade(dx), v = fade(dy);
  const double n =
      lerp(lerp(corner(0, 0), corner(1, 0), u), lerp(corner(0, 1), corner(1, 1), u), v);
  return std::clamp(n / kHalfSqrt2, -1.0, 1.0);
}

double PerlinNoise::noise3(const Vec3& p) const {
  return noise3(p, nullptr);
}

double PerlinNoise::noise3(const Vec3& p, Vec3* gradient) const {
  const Vec3 f(std::floor(p.x()), std::floor(p.y()), std::floor(p.z()));
  const int ix = static_cast<int>(f.x()), iy = static_cast<int>(f.y()),
            iz = static_cast<int>(f.z());
  const Vec3 d = p - f;
  // The eight corners' gradients and values g . (p - corner).
  double value[2][2][2];
  Vec3 grad[2][2][2];
  for (int cz = 0; cz < 2; ++cz)
    for (int cy = 0; cy < 2; ++cy)
      for (int cx = 0; cx < 2; ++cx) {
        const double* g = kGrad3[hash(ix + cx + hash(iy + cy + hash(iz + cz))) & 15u];
        grad[cz][cy][cx] = Vec3(g[0], g[1], g[2]) * kHalfSqrt2;  // unit
        value[cz][cy][cx] = grad[cz][cy][cx].dot(d - Vec3(cx, cy, cz));
      }
  const Vec3 w(fade(d.x()), fade(d.y()), fade(d.z()));
  // Trilinear interpolation of the corner values with the faded weights.
  double n = 0;
  Vec3 dn = Vec3::Zero();
  for (int cz = 0; cz < 2; ++cz)
    for (int cy = 0; cy < 2; ++cy)
      for (int cx = 0; cx < 2; ++cx) {
        const Vec3 wc(cx ? w.x() : 1 - w.x(), cy ? w.y() : 1 - w.y(), cz ? w.z() : 1 - w.z());
        const double weight = wc.x() * wc.y() * wc.z();
        const double v = value[cz][cy][cx];
        n += weight * v;
        if (gradient != nullptr) {
          // d(weight)/dp: the fade's slope, signed by the side of the corner.
          const Vec3 slope((cx ? 1 : -1) * fade_slope(d.x()) * wc.y() * wc.z(),
                           (cy ? 1 : -1) * fade_slope(d.y()) * wc.x() * wc.z(),
                           (cz ? 1 : -1) * fade_slope(d.z()) * wc.x() * wc.y());
          dn += slope * v + weight * grad[cz][cy][cx];
        }
      }
  if (gradient != nullptr) *gradient = dn / kHalfSqrt3;
  return std::clamp(n / kHalfSqrt3, -1.0, 1.0);
}

double fbm2(const NoiseParams& params, double x, double y) {
  check_params(params);
  const PerlinNoise noise(params.seed);
  double sum = 0, weights = 0, weight = 1, frequency = params.frequency;
  for (int o = 0; o < params.octaves; ++o) {
    // Each octave is shifted by an irrational offset so that lattice points (where gradient
    // noise is 0) do not line up across octaves.
    sum += weight * noise.noise2(x * frequency + 0.31830988 * o, y * frequency + 0.61803399 * o);
    weights += weight;
    weight *= params.persistence;
    frequency *= 2;
  }
  return params.amplitude * sum / weights;
}

double fbm3(const NoiseParams& params, const Vec3& p, Vec3* gradient) {
  check_params(params);
  const PerlinNoise noise(params.seed);
  double sum = 0, weights = 0, weight = 1, frequency = params.frequency;
  Vec3 dsum = Vec3::Zero();
  for (int o = 0; o < params.octaves; ++o) {
    const Vec3 shift = double(o) * Vec3(0.31830988, 0.61803399, 0.41421356);
    Vec3 g;
    sum += weight * noise.noise3(p * frequency + shift, gradient != nullptr ? &g : nullptr);
    if (gradient != nullptr) dsum += weight * frequency * g;
    weights += weight;
    weight *= params.persistence;
    frequency *= 2;
  }
  if (gradient != nullptr) *gradient = params.amplitude * dsum / weights;
  return params.amplitude * sum / weights;
}

double ring_falloff(double d, double radius) {
  const double inner = kRingInner * radius, outer = kRingOuter * radius;
  if (d <= inner) return 1;
  if (d >= outer) return 0;
  return 1 - (d - inner) / (outer - inner);  // eq 27
}

double NoisePlane::sample(double x, double y) const {
  const double cx = std::clamp(x, 0.0, double(cols)), cy = std::clamp(y, 0.0, double(rows));
  const int c0 = std::min(static_cast<int>(cx), cols - 1),
            r0 = std::min(static_cast<int>(cy), rows - 1);
  const double u = cx - c0, v = cy - r0;
  return lerp(lerp(at(r0, c0), at(r0, c0 + 1), u), lerp(at(r0 + 1, c0), at(r0 + 1, c0 + 1), u), v);
}

NoisePlane make_noise_plane(const NoiseParams& params, int rows, int cols, double radius) {
  if (rows < 1 || cols < 1 || !(radius > 0))
    throw std::invalid_argument("make_noise_plane: rows, cols >= 1 and radius > 0 needed");
  NoisePlane plane;
  plane.rows = rows;
  plane.cols = cols;
  plane.value.resize(size_t(rows + 1) * size_t(cols + 1));
  const double centre_col = 0.5 * cols, centre_row = 0.5 * rows;  // the paper's (ro/2, co/2)
  for (int r = 0; r <= rows; ++r)
    for (int c = 0; c <= cols; ++c) {
      const double d = std::hypot(c - centre_col, r - centre_row);
      const double falloff = ring_falloff(d, radius);
      plane.value[size_t(r) * size_t(cols + 1) + size_t(c)] =
          falloff > 0 ? falloff * fbm2(params, c, r) : 0.0;
    }
  return plane;
}

Bounds2 bounds_xy(const std::vector<Vec3>& points) {
  Bounds2 b;
  if (points.empty()) return b;
  b.min_x = b.max_x = points[0].x();
  b.min_y = b.max_y = points[0].y();
  for (const Vec3& p : points) {
    b.min_x = std::min(b.min_x, p.x());
    b.max_x = std::max(b.max_x, p.x());
    b.min_y = std::min(b.min_y, p.y());
    b.max_y = std::max(b.max_y, p.y());
  }
  return b;
}

Bounds2 plane_bounds(const NoisePlane& plane) {
  return {0, double(plane.cols), 0, double(plane.rows)};
}

Eigen::Vector2d map_to_plane(double x, double y, const Bounds2& surface, const Bounds2& plane) {
  auto map = [](double v, double lo, double hi, double plo, double phi) {
    if (!(hi > lo)) return 0.5 * (plo + phi);
    return plo + (v - lo) * (phi - plo) / (hi - lo);  // eqs 28, 29
  };
  return {map(x, surface.min_x, surface.max_x, plane.min_x, plane.max_x),
          map(y, surface.min_y, surface.max_y, plane.min_y, plane.max_y)};
}

std::vector<Vec3> disturb_fracture_points(const std::vector<Vec3>& points,
                                          const NoisePlane& plane) {
  const Bounds2 surface = bounds_xy(points), target = plane_bounds(plane);
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Vec3& p : points) {
    const Eigen::Vector2d xy = map_to_plane(p.x(), p.y(), surface, target);
    out.emplace_back(p.x(), p.y(), p.z() + plane.sample(xy.x(), xy.y()));  // eq 30
  }
  return out;
}

Vec3 HeightField::corner(int i, int j) const {
  return {min_x + i * cell_x, min_y + j * cell_y, at(i, j)};
}

std::vector<std::array<Vec3, 3>> HeightField::triangles() const {
  std::vector<std::array<Vec3, 3>> out;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const Vec3 a = corner(i, j + 1), b = corner(i + 1, j + 1), c = corner(i + 1, j),
                 d = corner(i, j);
      out.push_back({a, d, b});  // ABD, counter-clockwise from +z
      out.push_back({b, d, c});  // BCD
    }
  return out;
}

HeightField make_height_field(const std::vector<Vec3>& points, int nx, int ny) {
  if (nx < 1 || ny < 1 || points.empty())
    throw std::invalid_argument("make_height_field: nx, ny >= 1 and points needed");
  const Bounds2 b = bounds_xy(points);
  HeightField field;
  field.nx = nx;
  field.ny = ny;
  field.min_x = b.min_x;
  field.min_y = b.min_y;
  field.cell_x = (b.max_x - b.min_x) / nx;
  field.cell_y = (b.max_y - b.min_y) / ny;
  double min_z = std::numeric_limits<double>::infinity();
  for (const Vec3& p : points) min_z = std::min(min_z, p.z());
  field.height.assign(size_t(nx) * size_t(ny), min_z);
  auto cell = [](double v, double lo, double size, int n) {
    if (!(size > 0)) return 0;
    return std::clamp(static_cast<int>(std::floor((v - lo) / size)), 0, n - 1);
  };
  for (const Vec3& p : points) {
    const int i = cell(p.x(), b.min_x, field.cell_x, nx),
              j = cell(p.y(), b.min_y, field.cell_y, ny);
    double& h = field.height[size_t(j) * size_t(nx) + size_t(i)];
    h = std::max(h, p.z());
  }
  return field;
}

RoughSurfel rough_surfel(const NoiseParams& params, const FractureRegion& region, const Vec3& x,
                         const Vec3& normal) {
  RoughSurfel out;
  // The falloff and its gradient (eq 27 of the distance from the axis, or from the centre).
  Vec3 radial = x - region.centre;
  if (region.axis.squaredNorm() > 0) {
    const Vec3 a = region.axis.normalized();
    radial -= a * a.dot(radial);
  }
  const double d = radial.norm();
  out.falloff = region.radius > 0 ? ring_falloff(d, region.radius) : 1.0;
  Vec3 falloff_grad = Vec3::Zero();
  if (region.radius > 0 && out.falloff > 0 && out.falloff < 1 && d > 0) {
    falloff_grad = -radial / d / ((kRingOuter - kRingInner) * region.radius);
  }
  if (out.falloff == 0) {
    out.normal = normal;
    return out;
  }
  Vec3 noise_grad;
  const double noise = fbm3(params, x, &noise_grad);
  out.displacement = out.falloff * noise;
  const Vec3 grad = out.falloff * noise_grad + noise * falloff_grad;
  // The displaced surface x + h n has the normal n - grad_t h to first order.
  const Vec3 tangential = grad - normal * normal.dot(grad);
  out.normal = (normal - tangential).normalized();
  return out;
}

}  // namespace phyxel
