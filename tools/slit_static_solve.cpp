// slit_static_solve: the slit cantilever (scenes/validation/cantilever_slit.json) by a linear
// static solve of the MLS model: the small-strain energy of the CPU solver (elastic energy of
// each phyxel's gradient times its elastic volume, damage as the solver applies it, and the
// hourglass penalty) assembled as a sparse stiffness matrix and solved by LDLT, in seconds where
// relaxing takes minutes. The blade's pairs are the ones crossing x = 0.03 above z = 0 (ties
// through the front kept, as `blade_severs`). It measures how weights for the cut pairs near the
// front would change the tip deflection (docs/cutting.md, "Stiffness of a cut body"):
//   slit_static_solve M [none|transparency S0 POWER|diffraction LAMBDA] [--whole] [--no-damage]
//                     [--support H_OVER_SPACING]
// M odd: spacing 0.02 / M; S0 in spacings. Run from the repository root.
#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "engine/sampling/phyxel_set.h"
#include "engine/scene/scene.h"
#include "engine/solver/kernel.h"
#include "engine/solver/mls_model.h"
#include "engine/solver/neighbours.h"

using namespace phyxel;

namespace {

constexpr double kSlitX = 0.03, kFrontZ = 0.0, kReferenceTip = -7.0495e-3;

struct Options {
  int m = 7;
  std::string weight = "none";  // what a cut pair keeps: none, transparency, diffraction
  double s0 = 1.5, power = 2, lambda = 1;
  bool slit = true, damage = true;
  double support = 0;  // support radius in spacings; 0: the scene's (2)
};

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

// The small-strain stiffness of phyxel i's energy over its local dofs (i, then its live
// neighbours `js`): elastic volume * B^T D B plus the hourglass penalty.
Eigen::MatrixXd phyxel_stiffness(const std::vector<double>& ws, const std::vector<Vec3>& xs,
                                 const Eigen::Matrix3d& a_inv, double volume, double kappa,
                                 double lambda, double mu) {
  const int nl = int(ws.size()) + 1;
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(9, 3 * nl);  // G_rc at row 3 r + c
  for (int q = 0; q + 1 < nl; ++q) {
    const Vec3 c = ws[q] * a_inv * xs[q];
    for (int r = 0; r < 3; ++r)
      for (int s = 0; s < 3; ++s) {
        b(3 * r + s, 3 * (q + 1) + r) += c[s];
        b(3 * r + s, r) -= c[s];
      }
  }
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(9, 9);  // mu eps:eps + lambda/2 tr^2
  for (int r = 0; r < 3; ++r)
    for (int s = 0; s < 3; ++s) {
      d(3 * r + s, 3 * r + s) += mu;
      d(3 * r + s, 3 * s + r) += mu;
      d(4 * r, 4 * s) += lambda;
    }
  Eigen::MatrixXd k = volume * b.transpose() * d * b;
  for (int q = 0; q + 1 < nl; ++q) {  // e = G x_ij - (u_j - u_i)
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(3, 3 * nl);
    for (int r = 0; r < 3; ++r) {
      for (int s = 0; s < 3; ++s) e.row(r) += xs[q][s] * b.row(3 * r + s);
      e(r, 3 * (q + 1) + r) -= 1;
      e(r, r) += 1;
    }
    k += kappa * ws[q] * e.transpose() * e;
  }
  return k;
}

double solve_tip(const Options& o) {
  Scene scene = load_scene("scenes/validation/cantilever_slit.json");
  ObjectDesc& obj = scene.objects.at(0);
  obj.support_radius = o.support > 0 ? o.support * obj.spacing : obj.support_radius;
  obj.support_radius *= 7.0 / o.m;
  obj.spacing *= 7.0 / o.m;
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists nbr = find_rest_neighbours(set);
  const size_t n = set.size();
  const double h = obj.support_radius;
  const Material& mat = set.materials[0];
  const double lambda = lame_lambda(mat), mu = lame_mu(mat);
  std::vector<Eigen::Triplet<double>> entries;
  for (size_t i = 0; i < n; ++i) {
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero(), reference = Eigen::Matrix3d::Zero();
    std::vector<uint32_t> js{uint32_t(i)};
    std::vector<double> ws;
    std::vector<Vec3> xs;
    bool damaged = false;
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      const Vec3 x = set.rest[j] - set.rest[i];
      const double w0 = poly6(x.squaredNorm(), h);
      const double w = cut_pair_weight(o, set.rest[i], set.rest[j], w0, h, obj.spacing);
      reference += w0 * x * x.transpose();
      damaged = damaged || w != w0;
      if (w == 0) continue;
      a += w * x * x.transpose();
      js.push_back(j);
      ws.push_back(w);
      xs.push_back(x);
    }
    const double damage = damaged && o.damage ? damage_factor(min_moment_eigenvalue(a),
                                                              min_moment_eigenvalue(reference))
                                              : 1.0;
    const double kappa = damage * mat.hourglass * mu * set.volume[i] / (a.trace() / 3);
    const Eigen::MatrixXd k = phyxel_stiffness(ws, xs, regularised_inverse(a).inverse,
                                               damage * set.volume[i], kappa, lambda, mu);
    for (size_t q = 0; q < js.size(); ++q)
      for (size_t r = 0; r < js.size(); ++r) {
        if ((set.flags[js[q]] | set.flags[js[r]]) & kFixed) continue;
        for (int s = 0; s < 3; ++s)
          for (int t = 0; t < 3; ++t)
            entries.emplace_back(3 * js[q] + s, 3 * js[r] + t, k(3 * q + s, 3 * r + t));
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
                 "[--whole] [--no-damage] [--support H_OVER_SPACING]  (M odd >= 3)\n");
    return 2;
  }
  o.m = std::atoi(argv[1]);
  for (int k = 2; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--whole") o.slit = false;
    if (arg == "--no-damage") o.damage = false;
    if (arg == "--support" && k + 1 < argc) o.support = std::atof(argv[++k]);
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
    std::printf("M %d spacing %.3f mm, %s: tip u_z %.5e m", o.m, 20.0 / o.m,
                o.slit ? o.weight.c_str() : "whole beam", tip);
    if (o.slit) std::printf(", against CalculiX %+.2f %%", 100 * (tip / kReferenceTip - 1));
    std::printf("\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "slit_static_solve: %s\n", e.what());
    return 1;
  }
  return 0;
}
