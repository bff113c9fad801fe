// Shared pieces of the GPU solver tests: the Vulkan fixture (lavapipe + validation, zero
// validation messages per test), small scenes, and comparisons with the CPU reference.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "engine/solver/cpu_solver.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/physics/physics_fixtures.h"
#include "tests/vulkan/vulkan_test.h"

namespace phyxel::gpu::test {

using phyxel::test::box_scene;
using phyxel::test::box_shape;
using phyxel::test::tissue;

constexpr double kSpacing = 0.0025;

// A scene's run of `steps` on `gpu` with one aspirator: the run's result, the end state and
// the aspirator's force at every step (the paths' same-bits tests compare these).
struct AspirationRun {
  RunResult result;
  PointState state;
  std::vector<Vec3> forces;
};
inline AspirationRun run_aspirating(const Scene& scene, const PhyxelSet& set, GpuSolver& gpu,
                                    int64_t steps) {
  AspirationRun out;
  RunOptions run;
  run.steps = steps;
  run.on_tool_step = [&out](int64_t, double, const std::vector<ToolStepRecord>& records) {
    out.forces.push_back(records.at(0).force);
  };
  out.result = run_simulation(scene, set, gpu, run);
  out.state = gpu.read_state(false);
  return out;
}

// nx x ny x nz phyxels (a line when ny = nz = 1, one phyxel when all are 1).
inline Scene lattice_scene(int nx, int ny, int nz, const Material& m = tissue(),
                           double h_factor = 2.0) {
  const Vec3 hi = kSpacing * Vec3(nx - 1, ny - 1, nz - 1);
  return box_scene(Vec3(0.01, -0.02, 0.003), Vec3(0.01, -0.02, 0.003) + hi, kSpacing, m, h_factor);
}

inline PhyxelSet lattice(int nx, int ny, int nz, const Material& m = tissue(),
                         double h_factor = 2.0) {
  // Lines, plates and lone phyxels too: the tests of degenerate sets need them.
  return sample_scene(lattice_scene(nx, ny, nz, m, h_factor), SamplingOptions{false});
}

// A box with a stiffer spherical inclusion (two materials), no fixed phyxels, under gravity.
inline Scene two_material_scene() {
  Scene scene = lattice_scene(9, 7, 6, tissue(2e5, 0.35, 5.0));
  Inclusion inc;
  inc.name = "stiff";
  inc.shape.type = Shape::Type::Sphere;
  inc.shape.center = scene.objects[0].shape.min + Vec3(0.01, 0.0075, 0.006);
  inc.shape.radius = 0.005;
  inc.material = tissue(1e6, 0.45, 0.0);
  scene.objects[0].inclusions.push_back(inc);
  scene.simulation.gravity = Vec3(0, 0, -9.81);
  return scene;
}

inline double max_norm(const std::vector<Vec3>& x) {
  double m = 0;
  for (const Vec3& v : x) m = std::max(m, v.norm());
  return m;
}

template <class V>
double max_difference(const std::vector<Vec3>& a, const std::vector<V>& b) {
  double m = 0;
  for (size_t i = 0; i < a.size(); ++i)
    m = std::max(m, (a[i] - b[i].template cast<double>()).norm());
  return m;
}

inline double extent(const PhyxelSet& set) {
  Eigen::AlignedBox3d box;
  for (const Vec3& x : set.rest) box.extend(x);
  return box.sizes().maxCoeff();
}

// A smooth large deformation (stretch, shear, a rotation) plus per-phyxel noise, and a
// velocity field, reproducible from `seed`.
inline void deformed_state(const PhyxelSet& set, unsigned seed, double noise, std::vector<Vec3>& u,
                           std::vector<Vec3>& v) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> d(-1, 1);
  const Eigen::Matrix3d g =
      phyxel::test::random_matrix(rng, 0.05) +
      Eigen::AngleAxisd(0.3, Vec3(1, 2, 0.5).normalized()).toRotationMatrix() -
      Eigen::Matrix3d::Identity();
  const Vec3 c = set.rest[0];
  u.resize(set.size());
  v.resize(set.size());
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 x = set.rest[i] - c;
    u[i] = g * x + Vec3(0.2 * x.y() * x.y() / kSpacing * 0.05, 0, 0) +
           noise * Vec3(d(rng), d(rng), d(rng));
    v[i] = 0.01 * Vec3(d(rng), d(rng), d(rng));
  }
}

// The GPU's tool samples against the CPU's, substep by substep: over the samples `compare(cpu,
// gpu)` accepts, how far apart the ends of their axial ranges are (ToolContactSample::axial_min
// and axial_max; a blade's penetration depth): the worst difference within `tolerance` (m), how
// many are beyond it, and how many of the CPU's ranges are empty (min > max).
struct AxialAgreement {
  size_t compared = 0, outliers = 0, empty_on_cpu = 0;
  double worst = 0;
};
template <class Compare>
AxialAgreement axial_agreement(const std::vector<ToolContactSample>& cpu,
                               const std::vector<ToolContactSample>& gpu, double tolerance,
                               Compare compare) {
  AxialAgreement a;
  for (size_t k = 0; k < std::min(cpu.size(), gpu.size()); ++k) {
    const ToolContactSample &c = cpu[k], &g = gpu[k];
    if (!compare(c, g)) continue;
    ++a.compared;
    if (c.axial_min > c.axial_max) ++a.empty_on_cpu;
    const double d =
        std::max(std::abs(g.axial_min - c.axial_min), std::abs(g.axial_max - c.axial_max));
    if (d > tolerance)
      ++a.outliers;
    else
      a.worst = std::max(a.worst, d);
  }
  return a;
}

using phyxel::test::advance_tools_in_chunks;

class GpuSolverTest : public VulkanTest {};

}  // namespace phyxel::gpu::test
