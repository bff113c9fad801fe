#include "render/texture_map.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace phyxel::render {

Dome fit_dome(const std::vector<Vec3>& rest, const Vec3& axis) {
  Dome d;
  d.axis = axis.normalized();
  const Vec3 helper = std::abs(d.axis.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  d.e2 = d.axis.cross(helper).normalized();
  d.e1 = d.e2.cross(d.axis);
  if (rest.empty()) return d;
  // Bounds in the dome's frame.
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Vec3& x : rest) {
    const Vec3 l(x.dot(d.e1), x.dot(d.e2), x.dot(d.axis));
    lo = lo.cwiseMin(l);
    hi = hi.cwiseMax(l);
  }
  d.centre = 0.5 * (lo.x() + hi.x()) * d.e1 + 0.5 * (lo.y() + hi.y()) * d.e2 + lo.z() * d.axis;
  double r = 0;
  for (const Vec3& x : rest) r = std::max(r, (x - d.centre).norm());
  d.radius = r > 0 ? 1.001 * r : 1.0;
  d.p_height = 0;
  return d;
}

Vec3 sphere_point(const Vec3& q, double radius, double p_height) {
  const Vec3 p(0, 0, p_height);
  const Vec3 d = q - p;  // (c_x - x_1, c_y - y_1, c_z - z_1)
  const double dd = d.squaredNorm();
  if (!(dd > 0)) return Vec3::UnitZ();
  const double b = 2 * p.dot(d);
  const double mid = b * b - 4 * dd * (p.squaredNorm() - radius * radius);  // eq 6
  const double k = (-b + std::sqrt(std::max(mid, 0.0))) / (2 * dd);         // eq 5, + root
  return (p + k * d) / radius;                                              // eq 4, unit sphere
}

Eigen::Vector2d hemisphere_uv(const Vec3& x, double phi) {
  const double scale = 1.0 / (std::sqrt(std::max(1 + x.z(), 1e-12)) * std::sqrt(1 - std::cos(phi)));
  return {x.x() * scale, x.y() * scale};
}

Eigen::Vector2d dome_texcoord(const Dome& dome, const Vec3& world) {
  const Eigen::Vector2d uv =
      hemisphere_uv(sphere_point(dome.to_local(world), dome.radius, dome.p_height), dome.phi);
  return {0.5 * (uv.x() + 1), 0.5 * (1 - uv.y())};
}

Eigen::Matrix<double, 2, 3> dome_texcoord_gradient(const Dome& dome, const Vec3& world,
                                                   const Vec3& normal) {
  const double h = 1e-5 * dome.radius;
  Eigen::Matrix<double, 2, 3> g;
  for (int a = 0; a < 3; ++a) {
    const Vec3 step = h * Vec3::Unit(a);
    g.col(a) = (dome_texcoord(dome, world + step) - dome_texcoord(dome, world - step)) / (2 * h);
  }
  const double n2 = normal.squaredNorm();
  if (n2 > 0) {
    const Vec3 n = normal / std::sqrt(n2);
    g -= (g * n) * n.transpose();  // tangential part only
  }
  return g;
}

}  // namespace phyxel::render
