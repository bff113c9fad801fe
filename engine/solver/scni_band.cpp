#include "engine/solver/scni_band.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>

#include "engine/geometry/mesh_query.h"
#include "engine/solver/kernel.h"

namespace phyxel {

PointGrid::PointGrid(const std::vector<Vec3>& points, double h) : points_(points), h_(h) {
  for (uint32_t i = 0; i < points.size(); ++i) cells_[key(points[i])].push_back(i);
}

int64_t PointGrid::key(const Vec3& x) const {
  const Eigen::Array3d c = (x.array() / h_).floor();
  return key(int64_t(c.x()), int64_t(c.y()), int64_t(c.z()));
}

int64_t PointGrid::key(int64_t a, int64_t b, int64_t c) {
  constexpr int64_t kOffset = 1 << 20, kSpan = 1 << 21;
  return ((a + kOffset) * kSpan + b + kOffset) * kSpan + c + kOffset;
}

std::vector<uint32_t> PointGrid::within(const Vec3& x) const {
  // The cell of x once, then its 26 neighbours by index (shifting x by h and flooring again
  // can skip a cell through rounding).
  const Eigen::Array3d f = (x.array() / h_).floor();
  const int64_t cx = int64_t(f.x()), cy = int64_t(f.y()), cz = int64_t(f.z());
  std::vector<uint32_t> out;
  for (int64_t a = cx - 1; a <= cx + 1; ++a)
    for (int64_t b = cy - 1; b <= cy + 1; ++b)
      for (int64_t c = cz - 1; c <= cz + 1; ++c) {
        const auto it = cells_.find(key(a, b, c));
        if (it == cells_.end()) continue;
        for (const uint32_t j : it->second)
          if ((points_[j] - x).squaredNorm() < h_ * h_) out.push_back(j);
      }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::pair<uint32_t, double>> mls_shape_functions(const std::vector<Vec3>& rest,
                                                             const PointGrid& grid, double h,
                                                             const Vec3& x, const Vec3& from,
                                                             const PairWeight& weight) {
  Eigen::Matrix4d moment = Eigen::Matrix4d::Zero();
  std::vector<std::pair<uint32_t, double>> out;
  std::vector<Eigen::Vector4d> basis;
  for (const uint32_t j : grid.within(x)) {
    const Vec3& xj = rest[j];
    const double w0 = poly6((xj - x).squaredNorm(), h);
    const double w = w0 > 0 ? weight(from, j, w0) : 0.0;
    if (w == 0) continue;
    const Eigen::Vector4d p(1, xj.x() - x.x(), xj.y() - x.y(), xj.z() - x.z());
    moment += w * p * p.transpose();
    out.emplace_back(j, w);
    basis.push_back(p);
  }
  const Eigen::Vector4d r = moment.ldlt().solve(Eigen::Vector4d::UnitX());
  for (size_t k = 0; k < out.size(); ++k) out[k].second *= r.dot(basis[k]);
  return out;
}

std::vector<ScniBox> scni_boxes(const std::vector<Vec3>& rest, const PointGrid& grid, double h,
                                const ScniCell& cell, const PairWeight& weight) {
  const int np = cell.face_points, ns = cell.subcells;
  const double g = np == 1 ? 0.0 : 0.5 / std::sqrt(3.0);  // Gauss points at 1/2 -+ g
  const Vec3 step = (cell.hi - cell.lo) / ns;
  std::vector<std::map<uint32_t, Vec3>> boxes(size_t(ns * ns * ns));
  const auto sub = [ns](int a, int b, int c) { return size_t((a * ns + b) * ns + c); };
  for (int axis = 0; axis < 3; ++axis) {
    const int u1 = (axis + 1) % 3, u2 = (axis + 2) % 3;
    const double area = step[u1] * step[u2] / (np * np);
    for (int plane = 0; plane <= ns; ++plane) {
      // The cell's outer faces may be clamped: they contribute u = 0, nothing to G.
      if ((plane == 0 && cell.clamped[2 * axis]) || (plane == ns && cell.clamped[2 * axis + 1]))
        continue;
      for (int c1 = 0; c1 < ns; ++c1)
        for (int c2 = 0; c2 < ns; ++c2)
          for (int p = 0; p < np * np; ++p) {
            Vec3 x;
            x[axis] = cell.lo[axis] + plane * step[axis];
            x[u1] = cell.lo[u1] + (c1 + 0.5 + (p % np ? g : -g)) * step[u1];
            x[u2] = cell.lo[u2] + (c2 + 0.5 + (p / np ? g : -g)) * step[u2];
            const Vec3 from = x + 1e-7 * (cell.owner - x);
            const auto shape = mls_shape_functions(rest, grid, h, x, from, weight);
            for (int side = 0; side < 2; ++side) {  // the box below the plane (+n), above (-n)
              const int k = plane - 1 + side;
              if (k < 0 || k >= ns) continue;
              int idx[3];
              idx[axis] = k, idx[u1] = c1, idx[u2] = c2;
              auto& box = boxes[sub(idx[0], idx[1], idx[2])];
              for (const auto& [j, phi] : shape)
                box.try_emplace(j, Vec3::Zero()).first->second[axis] += (side ? -area : area) * phi;
            }
          }
    }
  }
  std::vector<ScniBox> out;
  const double volume = step.prod();
  for (const auto& box : boxes) {
    ScniBox b;
    b.volume = volume;
    for (const auto& [j, c] : box) {
      b.node.push_back(j);
      b.coeff.push_back(c / volume);
    }
    out.push_back(std::move(b));
  }
  return out;
}

ScniCell lattice_cell(const Vec3& x, double spacing, const Vec3& lo, const Vec3& hi) {
  ScniCell c;
  c.owner = x;
  c.lo = (x.array() - spacing / 2).max(lo.array());
  c.hi = (x.array() + spacing / 2).min(hi.array());
  return c;
}

double distance_to_quad(const Vec3& x, const std::array<Vec3, 4>& quad) {
  const double a = closest_point_on_triangle(x, quad[0], quad[1], quad[2]).distance_squared;
  const double b = closest_point_on_triangle(x, quad[0], quad[2], quad[3]).distance_squared;
  return std::sqrt(std::min(a, b));
}

}  // namespace phyxel
