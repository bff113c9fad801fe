// slit_static_solve: the slit cantilever (scenes/validation/cantilever_slit.json) by a linear
// static solve of the MLS model: the small-strain energy of the CPU solver (elastic energy of
// each phyxel's gradient times its elastic volume, damage as the solver applies it, and the
// hourglass penalty) assembled as a sparse stiffness matrix and solved by LDLT, in seconds where
// relaxing takes minutes. The blade's pairs are the ones crossing x = 0.03 above z = 0 (ties
// through the front kept, as `blade_severs`). It measures how weights for the cut pairs near the
// front would change the tip deflection, and, with --scni, a stabilised conforming nodal
// integration instead of the solver's (engine/solver/scni_band.h, the math of the solver's
// `cut_band`; docs/cutting.md, "Stiffness of a cut body"):
//   slit_static_solve M [none|transparency S0 POWER|diffraction LAMBDA] [--whole] [--no-damage]
//                     [--support H_OVER_SPACING] [--scni FACE_POINTS] [--subcells N]
//                     [--clamp-wall] [--near SPACINGS] [--patch]
// M odd: spacing 0.02 / M; S0 in spacings. Run from the repository root.
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

#include "engine/sampling/phyxel_set.h"
#include "engine/scene/scene.h"
#include "engine/solver/kernel.h"
#include "engine/solver/mls_model.h"
#include "engine/solver/neighbours.h"
#include "engine/solver/scni_band.h"

using namespace phyxel;

namespace {

constexpr double kSlitX = 0.03, kFrontZ = 0.0;
// CalculiX, 80 x 16 x 16 (scenes/validation/cantilever_slit_reference.json).
constexpr double kReferenceTip = -7.0495280e-3, kReferenceWholeTip = -3.7648790e-3;

struct Options {
  int m = 7;
  std::string weight = "none";  // what a cut pair keeps: none, transparency, diffraction
  double s0 = 1.5, power = 2, lambda = 1;
  bool slit = true, damage = true;
  double support = 0;       // support radius in spacings; 0: the scene's (2)
  bool scni = false;        // stabilised conforming nodal integration instead of the solver's
  int face_points = 1;      // per face and direction (1 or 2)
  int subcells = 1;         // boxes per cell and direction, each with its own smoothed strain
  bool clamp_wall = false;  // faces on the wall x = 0 take its displacement 0, not the MLS field
  bool patch = false;       // the linear patch test instead of the solve
  double near = 0;          // > 0: SCNI only within this many spacings of the slit, nodal elsewhere
};

// Distance from x to the slit's rectangle (plane x = kSlitX, z above the front).
double distance_to_slit(const Vec3& x) {
  return std::hypot(x.x() - kSlitX, std::max(0.0, kFrontZ - x.z()));
}

// The weight a pair keeps: w0 unless the slit crosses it above the front.
double cut_pair_weight(const Options& o, const Vec3& p, const Vec3& q, double w0, double h,
                       double spacing) {
  if (!o.slit || (p.x() - kSlitX) * (q.x() - kSlitX) >= 0) return w0;
  const double t = (kSlitX - p.x()) / (q.x() - p.x());
  const double above = p.z() + t * (q.z() - p.z()) - kFrontZ;  // crossing over the front
  if (above < 1e-6) return w0;
  if (o.weight == "transparency") {  // Organ et al. 1996: fades over s0 behind the front
    const double s0 = o.s0 * spacing;
    return above < s0 ? std::pow(1 - above / s0, o.power) * w0 : 0.0;
  }
  if (o.weight == "diffraction") {  // the distance around the front line
    const double s1 = std::hypot(p.x() - kSlitX, p.z() - kFrontZ);
    const double s2 = std::hypot(q.x() - kSlitX, q.z() - kFrontZ);
    const double around = std::hypot(s1 + s2, q.y() - p.y()), direct = (q - p).norm();
    const double d = std::pow(around / direct, o.lambda) * direct;
    return poly6(d * d, h);
  }
  return 0.0;
}

// V B^T D B: the small-strain elastic energy's stiffness for a gradient G = B u (G_rc at row
// 3 r + c), W = mu eps:eps + lambda/2 tr(eps)^2.
Eigen::MatrixXd elastic_stiffness(const Eigen::MatrixXd& b, double volume, double lambda,
                                  double mu) {
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(9, 9);
  for (int r = 0; r < 3; ++r)
    for (int s = 0; s < 3; ++s) {
      d(3 * r + s, 3 * r + s) += mu;
      d(3 * r + s, 3 * s + r) += mu;
      d(4 * r, 4 * s) += lambda;
    }
  return volume * b.transpose() * d * b;
}

// A phyxel's energy over its local dofs `nodes` (3 per node), as the stiffness k.
struct LocalStiffness {
  std::vector<uint32_t> nodes;
  Eigen::MatrixXd k;
};

struct Model {
  PhyxelSet set;
  NeighbourLists nbr;
  double h = 0, spacing = 0, lambda = 0, mu = 0, hourglass = 0;
};

// The solver's nodal integration: the MLS gradient of phyxel i from its live pairs, its
// elastic volume (with damage) and the hourglass penalty.
LocalStiffness nodal_stiffness(const Model& md, const Options& o, size_t i) {
  const PhyxelSet& set = md.set;
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero(), reference = Eigen::Matrix3d::Zero();
  LocalStiffness out{{uint32_t(i)}, {}};
  std::vector<double> ws;
  std::vector<Vec3> xs;
  bool damaged = false;
  for (uint32_t k = md.nbr.offset[i]; k < md.nbr.offset[i + 1]; ++k) {
    const uint32_t j = md.nbr.index[k];
    const Vec3 x = set.rest[j] - set.rest[i];
    const double w0 = poly6(x.squaredNorm(), md.h);
    const double w = cut_pair_weight(o, set.rest[i], set.rest[j], w0, md.h, md.spacing);
    reference += w0 * x * x.transpose();
    damaged = damaged || w != w0;
    if (w == 0) continue;
    a += w * x * x.transpose();
    out.nodes.push_back(j);
    ws.push_back(w);
    xs.push_back(x);
  }
  const double damage = damaged && o.damage ? damage_factor(min_moment_eigenvalue(a),
                                                            min_moment_eigenvalue(reference))
                                            : 1.0;
  const Eigen::Matrix3d a_inv = regularised_inverse(a).inverse;
  const int nl = int(out.nodes.size());
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(9, 3 * nl);
  for (int q = 1; q < nl; ++q) {
    const Vec3 c = ws[q - 1] * a_inv * xs[q - 1];
    for (int r = 0; r < 3; ++r)
      for (int s = 0; s < 3; ++s) {
        b(3 * r + s, 3 * q + r) += c[s];
        b(3 * r + s, r) -= c[s];
      }
  }
  out.k = elastic_stiffness(b, damage * set.volume[i], md.lambda, md.mu);
  const double kappa = damage * md.hourglass * md.mu * set.volume[i] / (a.trace() / 3);
  for (int q = 1; q < nl; ++q) {  // e = G x_ij - (u_j - u_i)
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(3, 3 * nl);
    for (int r = 0; r < 3; ++r) {
      for (int s = 0; s < 3; ++s) e.row(r) += xs[q - 1][s] * b.row(3 * r + s);
      e(r, 3 * q + r) -= 1;
      e(r, r) += 1;
    }
    out.k += kappa * ws[q - 1] * e.transpose() * e;
  }
  return out;
}

// A smoothed gradient over a box: its nodes and B (G_rc at row 3 r + c, 3 columns a node).
struct SmoothedGradient {
  std::vector<uint32_t> nodes;
  Eigen::MatrixXd b;
  double volume = 0;
};

// Stabilised conforming nodal integration (engine/solver/scni_band.h, shared with the solver's
// band): phyxel i's cell (its lattice cell clipped to the box) in `subcells`^3 boxes,
// `face_points`^2 Gauss points a face; the shape functions weight each phyxel as the cut pairs
// are (cut_pair_weight: the visibility criterion or diffraction at the slit). Faces on the
// clamped wall x = 0 take the wall's displacement 0 (--clamp-wall) or the MLS field.
std::vector<SmoothedGradient> scni_gradients(const Model& md, const PointGrid& grid,
                                             const Options& o, size_t i, const Vec3& box_min,
                                             const Vec3& box_max) {
  ScniCell cell = lattice_cell(md.set.rest[i], md.spacing, box_min, box_max);
  cell.subcells = o.subcells;
  cell.face_points = o.face_points;
  cell.clamped[0] = o.clamp_wall && std::abs(cell.lo.x() - box_min.x()) < 1e-12;
  const PairWeight weight = [&](const Vec3& from, uint32_t j, double w0) {
    return cut_pair_weight(o, from, md.set.rest[j], w0, md.h, md.spacing);
  };
  std::vector<SmoothedGradient> out;
  for (const ScniBox& box : scni_boxes(md.set.rest, grid, md.h, cell, weight)) {
    SmoothedGradient sg{box.node, Eigen::MatrixXd::Zero(9, 3 * long(box.node.size())), box.volume};
    for (size_t q = 0; q < box.node.size(); ++q)
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) sg.b(3 * r + c, 3 * long(q) + r) = box.coeff[q][c];
    out.push_back(std::move(sg));
  }
  return out;
}

// The energy of phyxel i's cell: the sum over its boxes; no hourglass penalty.
LocalStiffness scni_stiffness(const Model& md, const PointGrid& grid, const Options& o, size_t i,
                              const Vec3& box_min, const Vec3& box_max) {
  const auto boxes = scni_gradients(md, grid, o, i, box_min, box_max);
  std::map<uint32_t, long> column;
  for (const auto& sg : boxes)
    for (const uint32_t j : sg.nodes) column.try_emplace(j, 0);
  LocalStiffness out;
  for (auto& [j, c] : column) c = 3 * long(out.nodes.size()), out.nodes.push_back(j);
  out.k = Eigen::MatrixXd::Zero(3 * long(out.nodes.size()), 3 * long(out.nodes.size()));
  for (const auto& sg : boxes) {
    Eigen::MatrixXd b = Eigen::MatrixXd::Zero(9, out.k.cols());
    for (size_t q = 0; q < sg.nodes.size(); ++q)
      b.block(0, column[sg.nodes[q]], 9, 3) = sg.b.block(0, 3 * long(q), 9, 3);
    out.k += elastic_stiffness(b, sg.volume, md.lambda, md.mu);
  }
  return out;
}

// The linear patch test of the smoothed gradients: nodal values of u = A x, A fixed; the largest
// |G - A| / |A| over the boxes of interior cells and over those of cells on the body's surface.
void patch_test(const Model& md, const PointGrid& grid, const Options& o, const Vec3& box_min,
                const Vec3& box_max) {
  Eigen::Matrix3d a;
  a << 0.3, -0.1, 0.7, 0.2, -0.5, 0.1, 0.4, 0.6, -0.2;
  double worst[2] = {0, 0};
  for (size_t i = 0; i < md.set.size(); ++i) {
    const Vec3 xi = md.set.rest[i];
    const bool surface =
        ((xi - box_min).array().abs() < 1e-9).any() || ((xi - box_max).array().abs() < 1e-9).any();
    for (const auto& sg : scni_gradients(md, grid, o, i, box_min, box_max)) {
      Eigen::VectorXd u(3 * long(sg.nodes.size()));
      for (size_t q = 0; q < sg.nodes.size(); ++q)
        u.segment<3>(3 * long(q)) = a * md.set.rest[sg.nodes[q]];
      const Eigen::VectorXd g = sg.b * u;
      const Eigen::Matrix3d gm = Eigen::Map<const Eigen::Matrix3d>(g.data()).transpose();
      worst[surface] = std::max(worst[surface], (gm - a).norm() / a.norm());
    }
  }
  std::printf("patch test, largest |G - A| / |A|: interior cells %.2e, surface cells %.2e\n",
              worst[0], worst[1]);
}

double solve_tip(const Options& o) {
  Scene scene = load_scene("scenes/validation/cantilever_slit.json");
  ObjectDesc& obj = scene.objects.at(0);
  obj.support_radius = o.support > 0 ? o.support * obj.spacing : obj.support_radius;
  obj.support_radius *= 7.0 / o.m;
  obj.spacing *= 7.0 / o.m;
  Model md{sample_scene(scene), {}, obj.support_radius, obj.spacing, 0, 0, 0};
  md.nbr = find_rest_neighbours(md.set);
  const Material& mat = md.set.materials[0];
  md.lambda = lame_lambda(mat), md.mu = lame_mu(mat), md.hourglass = mat.hourglass;
  const size_t n = md.set.size();
  const PhyxelSet& set = md.set;
  const PointGrid grid(set.rest, md.h);
  if (o.patch) {
    patch_test(md, grid, o, obj.shape.min, obj.shape.max);
    return 0;
  }
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < n; ++i) {
    const bool scni =
        o.scni && (o.near <= 0 || distance_to_slit(set.rest[i]) < o.near * obj.spacing);
    const LocalStiffness l = scni ? scni_stiffness(md, grid, o, i, obj.shape.min, obj.shape.max)
                                  : nodal_stiffness(md, o, i);
    for (size_t q = 0; q < l.nodes.size(); ++q)
      for (size_t r = 0; r < l.nodes.size(); ++r) {
        if ((set.flags[l.nodes[q]] | set.flags[l.nodes[r]]) & kFixed) continue;
        for (int s = 0; s < 3; ++s)
          for (int t = 0; t < 3; ++t)
            entries.emplace_back(3 * l.nodes[q] + s, 3 * l.nodes[r] + t, l.k(3 * q + s, 3 * r + t));
      }
  }
  Eigen::VectorXd f = Eigen::VectorXd::Zero(3 * long(n));
  for (size_t i = 0; i < n; ++i) {
    if (set.flags[i] & kFixed)
      for (int s = 0; s < 3; ++s) entries.emplace_back(3 * i + s, 3 * i + s, 1.0);
    else
      f[3 * long(i) + 2] = set.mass[i] * scene.simulation.gravity.z();
  }
  Eigen::SparseMatrix<double> stiffness(3 * long(n), 3 * long(n));
  stiffness.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(stiffness);
  if (ldlt.info() != Eigen::Success) throw std::runtime_error("the stiffness is singular");
  const Eigen::VectorXd u = ldlt.solve(f);
  double sum = 0;  // the mean u_z of the phyxels round the tip's centre line, as the bench
  int count = 0;
  for (size_t i = 0; i < n; ++i)
    if ((set.rest[i] - Vec3(0.1, 0, 0)).norm() < 0.75 * obj.spacing)
      sum += u[3 * long(i) + 2], ++count;
  return sum / count;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  if (argc < 2 || std::atoi(argv[1]) < 3 || std::atoi(argv[1]) % 2 == 0) {
    std::fprintf(stderr,
                 "usage: slit_static_solve M [none|transparency S0 POWER|diffraction LAMBDA] "
                 "[--whole] [--no-damage] [--support H_OVER_SPACING] [--scni 1|2] [--subcells N] "
                 "[--clamp-wall] [--near SPACINGS] [--patch]  (M odd >= 3)\n");
    return 2;
  }
  o.m = std::atoi(argv[1]);
  for (int k = 2; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--whole") o.slit = false;
    if (arg == "--no-damage") o.damage = false;
    if (arg == "--support" && k + 1 < argc) o.support = std::atof(argv[++k]);
    if (arg == "--scni" && k + 1 < argc)
      o.scni = true, o.face_points = std::atoi(argv[++k]) == 2 ? 2 : 1;
    if (arg == "--subcells" && k + 1 < argc) o.subcells = std::max(1, std::atoi(argv[++k]));
    if (arg == "--clamp-wall") o.clamp_wall = true;
    if (arg == "--near" && k + 1 < argc) o.near = std::atof(argv[++k]);
    if (arg == "--patch") o.patch = o.scni = true;
    if (arg == "transparency" && k + 2 < argc) {
      o.weight = arg;
      o.s0 = std::atof(argv[++k]);
      o.power = std::atof(argv[++k]);
    }
    if (arg == "diffraction" && k + 1 < argc) {
      o.weight = arg;
      o.lambda = std::atof(argv[++k]);
    }
  }
  try {
    const double tip = solve_tip(o);
    if (o.patch) return 0;
    std::printf("M %d spacing %.3f mm, %s%s: tip u_z %.5e m", o.m, 20.0 / o.m,
                o.scni ? "SCNI, " : "", o.slit ? o.weight.c_str() : "whole beam", tip);
    std::printf(", against CalculiX %+.2f %%",
                100 * (tip / (o.slit ? kReferenceTip : kReferenceWholeTip) - 1));
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "slit_static_solve: %s\n", e.what());
    return 1;
  }
  return 0;
}
