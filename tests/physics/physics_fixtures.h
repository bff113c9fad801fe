// Small scenes built in code for the physics property tests.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>

#include "engine/sampling/phyxel_set.h"
#include "engine/scene/scene.h"
#include "engine/solver/cpu_solver.h"

namespace phyxel::test {

inline Shape box_shape(const Vec3& lo, const Vec3& hi) {
  Shape s;
  s.type = Shape::Type::Box;
  s.min = lo;
  s.max = hi;
  return s;
}

inline Material tissue(double young = 1e6, double poisson = 0.3, double damping = 0) {
  Material m;
  m.young = young;
  m.poisson = poisson;
  m.density = 1000;
  m.damping = damping;
  return m;
}

// One box object sampled with spacing s and support radius h_factor * s.
inline Scene box_scene(const Vec3& lo, const Vec3& hi, double s, const Material& m,
                       double h_factor = 2.0) {
  Scene scene;
  scene.simulation.dt = 1e-5;
  scene.simulation.steps = 1;
  ObjectDesc o;
  o.name = "box";
  o.shape = box_shape(lo, hi);
  o.spacing = s;
  o.support_radius = h_factor * s;
  o.material = m;
  scene.objects.push_back(o);
  return scene;
}

// A fresh, empty folder for a test's files under $PHYXEL_TEST_OUT (set by ctest).
inline std::filesystem::path test_output_dir(const std::string& name) {
  const char* root = std::getenv("PHYXEL_TEST_OUT");
  const std::filesystem::path dir = std::filesystem::path(root ? root : "/tmp") / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline Eigen::Matrix3d random_matrix(std::mt19937& rng, double scale) {
  std::uniform_real_distribution<double> d(-scale, scale);
  Eigen::Matrix3d m;
  for (int i = 0; i < 9; ++i) m.data()[i] = d(rng);
  return m;
}

// Largest eigenvalue of M^-1 K at rest by power iteration on the linearised forces, over the
// free phyxels (fixed ones stay at 0); its square root, rad/s.
inline double max_angular_frequency(CpuSolver<double>& solver, const PhyxelSet& set) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> d(-1, 1);
  std::vector<Vec3> x(set.size(), Vec3::Zero());
  for (size_t i = 0; i < set.size(); ++i)
    if (!(set.flags[i] & kFixed)) x[i] = Vec3(d(rng), d(rng), d(rng));
  double lambda = 0;
  const double eps = 1e-9;
  for (int it = 0; it < 300; ++it) {
    double norm = 0;
    for (const Vec3& v : x) norm += v.squaredNorm();
    norm = std::sqrt(norm);
    for (size_t i = 0; i < set.size(); ++i) solver.displacement()[i] = eps * x[i] / norm;
    solver.compute_forces();
    double dot = 0;
    for (size_t i = 0; i < set.size(); ++i) {
      if (set.flags[i] & kFixed) continue;
      const Vec3 kx = -solver.force()[i] / eps / set.mass[i];  // M^-1 K x / |x|
      dot += kx.dot(x[i]) / norm;
      x[i] = kx;
    }
    lambda = dot;
  }
  return std::sqrt(std::max(lambda, 0.0));
}

}  // namespace phyxel::test
