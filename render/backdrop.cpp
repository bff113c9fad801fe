#include "render/backdrop.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>

#include "engine/geometry/mesh.h"
#include "engine/geometry/shape.h"

namespace phyxel::render {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Disc radius over the diagonal of a box face's grid cell (0.5 would just cover it): the
// discs of neighbours overlap enough that their colours blend, and no more (each overlap costs
// the splat passes a ray-disc test and the accumulation its atomics, per pixel).
constexpr double kGridRadius = 0.55;
// Disc radius over the local spacing of the Fibonacci lattice and of mesh samples.
constexpr double kScatterRadius = 0.85;

uint32_t hash3(int32_t x, int32_t y, int32_t z) {
  uint32_t h = static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^
               static_cast<uint32_t>(z) * 0xcb1ab31fu;
  h ^= h >> 15;
  h *= 0x2c1b3c6du;
  h ^= h >> 12;
  h *= 0x297a2d39u;
  h ^= h >> 15;
  return h;
}

double hash_unit(int32_t x, int32_t y, int32_t z) {
  return double(hash3(x, y, z) & 0xffffffu) / double(0x1000000);
}

// Value noise in [0, 1], smooth (trilinear with a smoothstep), cells of size 1.
double value_noise(const Vec3& p) {
  const Vec3 f = p.array().floor();
  const auto i = f.cast<int32_t>();
  Vec3 t = p - f;
  t = t.array() * t.array() * (3.0 - 2.0 * t.array());
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    const double w = (dx ? t.x() : 1 - t.x()) * (dy ? t.y() : 1 - t.y()) * (dz ? t.z() : 1 - t.z());
    sum += w * hash_unit(i.x() + dx, i.y() + dy, i.z() + dz);
  }
  return sum;
}

// Three octaves of value noise, in [0, 1], features of about `scale` metres.
double fbm(const Vec3& p, double scale) {
  const Vec3 q = p / scale;
  return (4 * value_noise(q) + 2 * value_noise(2.03 * q + Vec3(17.1, 3.7, 9.2)) +
          value_noise(4.01 * q + Vec3(5.3, 11.9, 2.1))) /
         7;
}

// The per-splat grain of a weave or a speckle, in [0, 1), from the position on a 0.5 mm grid.
double grain(const Vec3& p) {
  const Vec3 q = (p / 5e-4).array().floor();
  return hash_unit(int32_t(q.x()), int32_t(q.y()), int32_t(q.z()));
}

// The height of a drape's folds, about -1 ... 1: sharp-crested, wandering ridges every ~6 cm
// (1 - |sin| crests like cloth laid over), crossed by softer, longer creases; smooth enough
// that neighbouring discs (centimetres apart) tilt alike.
double fold_height(const Vec3& p) {
  const Vec3 d1 = Vec3(0.83, 0.45, 0.33).normalized(), d2 = Vec3(-0.3, 0.9, 0.3).normalized();
  const double ridge = 1 - 2 * std::abs(std::sin(kPi * p.dot(d1) / 0.06 + 4.0 * fbm(p, 0.09)));
  const double crease = std::sin(2 * kPi * p.dot(d2) / 0.11 + 3.0 * fbm(p, 0.07));
  return 0.55 * ridge + 0.3 * crease + 0.15 * (2 * fbm(p, 0.04) - 1);
}

Vec3 mix(const Vec3& a, const Vec3& b, double t) {
  return a + (b - a) * t;
}

double margin(const BackdropItem& item, const Vec3& p, double width) {
  if (!item.hole) return 0;
  return std::clamp(1 - distance_to_surface(*item.hole, p) / width, 0.0, 1.0);
}

// Thomsen's approximation of an ellipsoid's area (within about 1 %).
double ellipsoid_area(const Vec3& r) {
  constexpr double p = 1.6075;
  const double a = std::pow(r.x(), p), b = std::pow(r.y(), p), c = std::pow(r.z(), p);
  return 4 * kPi * std::pow((a * b + a * c + b * c) / 3, 1 / p);
}

void sample_box(const Shape& s, double spacing, std::vector<BackdropSample>& out) {
  const Vec3 size = s.max - s.min;
  for (int a = 0; a < 3; ++a) {
    const int u = (a + 1) % 3, v = (a + 2) % 3;
    const int nu = std::max(1, int(std::lround(size[u] / spacing)));
    const int nv = std::max(1, int(std::lround(size[v] / spacing)));
    const double du = size[u] / nu, dv = size[v] / nv;
    const double radius = kGridRadius * std::hypot(du, dv);
    for (const int side : {-1, 1}) {
      Vec3 n = Vec3::Zero();
      n[a] = side;
      for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
          Vec3 p;
          p[a] = side < 0 ? s.min[a] : s.max[a];
          p[u] = s.min[u] + (i + 0.5) * du;
          p[v] = s.min[v] + (j + 0.5) * dv;
          out.push_back({p, n, radius});
        }
      }
    }
  }
}

// A Fibonacci lattice on the unit sphere mapped onto the ellipsoid; each sample's disc is
// sized by the local area stretch of the map (abc |D^-1 u| per unit of sphere area).
void sample_ellipsoid(const Vec3& centre, const Vec3& radii, double spacing,
                      std::vector<BackdropSample>& out) {
  const double area = ellipsoid_area(radii);
  const auto n = std::max<int64_t>(4, std::llround(area / (spacing * spacing)));
  const double golden = kPi * (3 - std::sqrt(5.0));
  const double cell = 4 * kPi / double(n);  // sphere area per sample
  const double abc = radii.prod();
  for (int64_t k = 0; k < n; ++k) {
    const double z = 1 - (2 * double(k) + 1) / double(n);
    const double r = std::sqrt(std::max(0.0, 1 - z * z));
    const double phi = golden * double(k);
    const Vec3 u(r * std::cos(phi), r * std::sin(phi), z);
    const Vec3 q = u.cwiseQuotient(radii);
    const double local = std::sqrt(abc * q.norm() * cell);
    out.push_back({centre + radii.cwiseProduct(u), q.normalized(), kScatterRadius * local});
  }
}

// Per triangle, its share of area / spacing^2 samples (the fractions carried on), placed by
// the R2 low-discrepancy sequence folded into the triangle.
void sample_mesh(const TriangleMesh& mesh, double spacing, std::vector<BackdropSample>& out) {
  constexpr double a1 = 0.7548776662466927, a2 = 0.5698402909980532;
  double carry = 0;
  int64_t j = 0;
  for (const Eigen::Vector3i& t : mesh.triangles) {
    const Vec3 &v0 = mesh.vertices[t[0]], &v1 = mesh.vertices[t[1]], &v2 = mesh.vertices[t[2]];
    const Vec3 cross = (v1 - v0).cross(v2 - v0);
    const double area = 0.5 * cross.norm();
    if (!(area > 0)) continue;
    carry += area / (spacing * spacing);
    const auto count = static_cast<int64_t>(std::floor(carry));
    carry -= double(count);
    for (int64_t k = 0; k < count; ++k, ++j) {
      double a = std::fmod(0.5 + a1 * double(j), 1.0), b = std::fmod(0.5 + a2 * double(j), 1.0);
      if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
      }
      out.push_back(
          {v0 + a * (v1 - v0) + b * (v2 - v0), cross.normalized(), kScatterRadius * spacing});
    }
  }
}

}  // namespace

std::vector<BackdropSample> sample_backdrop_surface(const Shape& shape, double spacing) {
  if (!(spacing > 0) || !std::isfinite(spacing)) {
    throw std::invalid_argument("sample_backdrop_surface: spacing must be > 0");
  }
  std::vector<BackdropSample> out;
  switch (shape.type) {
    case Shape::Type::Box:
      sample_box(shape, spacing, out);
      break;
    case Shape::Type::Sphere:
      sample_ellipsoid(shape.center, Vec3::Constant(shape.radius), spacing, out);
      break;
    case Shape::Type::Ellipsoid:
      sample_ellipsoid(shape.center, shape.radii, spacing, out);
      break;
    case Shape::Type::Mesh:
      if (shape.mesh) sample_mesh(*shape.mesh, spacing, out);
      break;
    case Shape::Type::Image:  // refused by the scene reader (no surface to draw)
      break;
  }
  return out;
}

double distance_to_surface(const Shape& shape, const Vec3& p) {
  switch (shape.type) {
    case Shape::Type::Box: {
      const Vec3 c = 0.5 * (shape.min + shape.max), h = 0.5 * (shape.max - shape.min);
      const Vec3 q = (p - c).cwiseAbs() - h;
      const double outside = q.cwiseMax(0.0).norm();
      return outside > 0 ? outside : -q.maxCoeff();
    }
    case Shape::Type::Sphere:
      return std::abs((p - shape.center).norm() - shape.radius);
    case Shape::Type::Ellipsoid: {
      const Vec3 d = p - shape.center;
      const double q = d.cwiseQuotient(shape.radii).norm();
      if (!(q > 0)) return shape.radii.minCoeff();
      return std::abs(q - 1) * d.norm() / q;  // along the ray from the centre
    }
    case Shape::Type::Mesh:
    case Shape::Type::Image:
      break;
  }
  return std::numeric_limits<double>::infinity();
}

BakedLook bake_look(const BackdropItem& item, const BackdropSample& s) {
  const Vec3& p = s.position;
  const Vec3& base = item.colour;
  BakedLook out{base, s.normal};
  switch (item.look) {
    case BackdropItem::Look::Drape: {
      // Folds: the normal tilted by the fold height's gradient along the surface (finite
      // differences), the colour darker in the creases; a weave grain of a few per cent; a
      // darker hem where the cloth meets the window cut into it.
      const Vec3 t1 = s.normal.unitOrthogonal(), t2 = s.normal.cross(t1);
      constexpr double h = 5e-4, amplitude = 0.0025;
      const double f = fold_height(p);
      const double g1 = (fold_height(p + h * t1) - f) / h, g2 = (fold_height(p + h * t2) - f) / h;
      out.normal = (s.normal - amplitude * (g1 * t1 + g2 * t2)).normalized();
      const double shade = 0.78 + 0.22 * std::clamp(0.5 + 0.5 * f, 0.0, 1.0);
      const double weave = 0.98 + 0.04 * grain(p);
      const double hem = 1 - 0.25 * margin(item, p, 0.006);
      out.colour = base * (shade * weave * hem);
      break;
    }
    case BackdropItem::Look::Skin: {
      // Mottled, a little redder in patches; the cut edge at the hole bloody.
      const double m = fbm(p, 0.006);
      out.colour = base * (0.9 + 0.15 * m) + Vec3(0.05, -0.02, -0.02) * fbm(p, 0.02);
      out.colour = mix(out.colour, Vec3(0.62, 0.16, 0.13), std::pow(margin(item, p, 0.005), 2));
      break;
    }
    case BackdropItem::Look::Bone: {
      // Porous speckle; the sawn edge at the hole darker, tinged with blood.
      out.colour = base * (0.88 + 0.14 * fbm(p, 0.003)) * (grain(p) < 0.12 ? 0.85 : 1.0);
      out.colour = mix(out.colour, Vec3(0.72, 0.45, 0.36), margin(item, p, 0.003));
      break;
    }
    case BackdropItem::Look::Tissue: {
      out.colour = base * (0.75 + 0.4 * fbm(p, 0.005));
      break;
    }
  }
  out.colour = out.colour.cwiseMax(0.0).cwiseMin(1.0);
  return out;
}

std::vector<layout::Splat> bake_backdrop(const std::vector<BackdropItem>& items, const Vec3& eye) {
  std::vector<layout::Splat> splats;
  const float flags = float(layout::kSplatBaked | layout::kSplatUsable);
  for (const BackdropItem& item : items) {
    for (const BackdropSample& s : sample_backdrop_surface(item.shape, item.spacing)) {
      if (!(s.normal.dot(eye - s.position) > 0)) continue;  // faces away from the camera
      if (item.hole && shape_contains(*item.hole, s.position)) continue;
      if (item.within && !shape_contains(*item.within, s.position)) continue;
      const BakedLook look = bake_look(item, s);
      layout::Splat sp{};
      sp.centre = {float(s.position.x()), float(s.position.y()), float(s.position.z()),
                   float(s.radius)};
      sp.normal = {float(look.normal.x()), float(look.normal.y()), float(look.normal.z()), flags};
      sp.ds_dx = {float(look.colour.x()), float(look.colour.y()), float(look.colour.z()), 0.0f};
      splats.push_back(sp);
    }
  }
  return splats;
}

}  // namespace phyxel::render
