// paper_measurements: figures behind what the project does instead of the paper's section V.D
// octree, its eq 23 and its section V.C height field (docs/decisions.md, "What the paper has and
// Phyxel does not"). One thread, medians of 5 repeats, microseconds of the thread's CPU time.
//
// paper_measurements octree [sizes...]   (default 10000 100000 1000000 phyxels)
//   Per lattice box (as `phyxel bench` makes it):
//   cut          CpuSolver::sever_pairs of the pairs crossing a 1 cm x 1 cm patch of a plane,
//                less the force recomputation it ends with (timed on its own): the severing
//                and the precompute of the touched phyxels, a cut's topology update;
//   aspiration   CpuSolver::remove_phyxels of a ball at the top (radius 4 mm, the brain scene's
//                reach, or 1.5 spacings where that is more), likewise less the forces (its
//                pass lists are rebuilt);
//   octree build the paper's octree over the same phyxels: one leaf per phyxel, each node
//                with the paper's fields (flag, coordinate, radius, child and parent links,
//                colour, mass, volume, normal), built top-down by octant partition;
//   octree edit  the paper's update for the same ball: up from the leaf nearest the collision
//                point to the first ancestor whose cell holds the ball (the paper: larger than
//                R), its leaves within R deleted and emptied parents removed, those within
//                R + delta flagged.
//   Each repeat edits a fresh patch or ball.
//
// paper_measurements eq23
//   A 1 cm cube (E = 10 kPa, nu = 0.3, spacings 2 and 1 mm) stretched 10 % along x, u = 0.1 x:
//   the solver's force on the phyxel in the middle of the +x face, and the paper's eq 23,
//   -v_i sigma_i grad u_i eps_i, at the same phyxel (sigma of eq 12 from the Green strain).
//
// paper_measurements height-field
//   An aspirator descends 6 mm into a block (the suction test's, tear stress 1 kPa) on the CPU;
//   the fracture surface left at the end (exposed and not aspirated later) is projected along
//   the tool's axis onto cells of one spacing as eqs 28-30's height field does (the largest
//   height per cell): how many of its phyxels lie more than 0.5 and 1.5 spacings below their
//   cell's height, i.e. would not be drawn (beyond 1.5: a layer of its own, not the shell's
//   thickness).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "engine/run/simulation.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/scene/scene.h"
#include "engine/solver/cpu_solver.h"
#include "engine/solver/solver.h"
#include "engine/surgery/aspiration.h"
#include "engine/surgery/fracture_surface.h"

namespace {

using phyxel::Vec3;

// Microseconds of CPU time this thread has used: on a loaded machine the wall clock also counts
// the time other processes ran; one thread does all the work timed here.
double thread_micros() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) * 1e6 + double(t.tv_nsec) * 1e-3;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// The box of `phyxel bench` (0.1 m, spacing 0.1 / (n^(1/3) - 1)), base clamped.
phyxel::Scene box_scene(long phyxels) {
  const int per_side = std::max(2, int(std::lround(std::cbrt(double(phyxels)))));
  const double spacing = 0.1 / (per_side - 1);
  const std::string json =
      R"({"simulation": {"dt": 1e-5, "steps": 1, "gravity": [0, 0, 0]},
  "objects": [{"name": "box", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.1, 0.1, 0.1]},
    "spacing": )" +
      std::to_string(spacing) + R"(,
    "material": {"young": 1e5, "poisson": 0.3, "density": 1000, "damping": 1},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 1e-6]}]}],
  "output": {"every": 0}})";
  return phyxel::parse_scene(json, "box.json");
}

// The paper's octree node (section V.D): one leaf per phyxel.
struct OctreeNode {
  uint32_t flag = 0;  // 1: surface
  Vec3 coordinate = Vec3::Zero();
  double radius = 0;  // half the cell's side
  std::array<int32_t, 8> child{-1, -1, -1, -1, -1, -1, -1, -1};
  int32_t parent = -1;
  std::array<float, 3> colour{};
  double mass = 0, volume = 0;
  Vec3 normal = Vec3::Zero();
  int32_t phyxel = -1;  // leaves
};

struct Octree {
  std::vector<OctreeNode> nodes;
  std::vector<int32_t> leaf_of;  // per phyxel

  int32_t build(const phyxel::PhyxelSet& set, std::vector<uint32_t>& ids, size_t begin, size_t end,
                const Vec3& centre, double half, int32_t parent) {
    const int32_t at = int32_t(nodes.size());
    nodes.emplace_back();
    nodes[at].coordinate = centre;
    nodes[at].radius = half;
    nodes[at].parent = parent;
    if (end - begin == 1 || half < 1e-9) {
      const uint32_t i = ids[begin];
      nodes[at].phyxel = int32_t(i);
      nodes[at].flag = (set.flags[i] & phyxel::kSurface) != 0;
      nodes[at].mass = set.mass[i];
      nodes[at].volume = set.volume[i];
      leaf_of[i] = at;
      return at;
    }
    auto octant = [&](uint32_t i) {
      const Vec3& x = set.rest[i];
      return (x.x() >= centre.x()) | (x.y() >= centre.y()) << 1 | (x.z() >= centre.z()) << 2;
    };
    std::array<size_t, 9> start{};
    for (size_t k = begin; k < end; ++k) ++start[octant(ids[k]) + 1];
    for (int o = 0; o < 8; ++o) start[o + 1] += start[o];
    std::vector<uint32_t> sorted(end - begin);
    std::array<size_t, 8> fill{};
    for (size_t k = begin; k < end; ++k) {
      const int o = octant(ids[k]);
      sorted[start[o] + fill[o]++] = ids[k];
    }
    std::copy(sorted.begin(), sorted.end(), ids.begin() + long(begin));
    for (int o = 0; o < 8; ++o) {
      if (start[o + 1] == start[o]) continue;
      const Vec3 c = centre + 0.5 * half * Vec3(o & 1 ? 1 : -1, o & 2 ? 1 : -1, o & 4 ? 1 : -1);
      const int32_t child =
          build(set, ids, begin + start[o], begin + start[o + 1], c, 0.5 * half, at);
      nodes[at].child[o] = child;
    }
    return at;
  }

  explicit Octree(const phyxel::PhyxelSet& set) : leaf_of(set.size(), -1) {
    Eigen::AlignedBox3d box;
    for (const Vec3& x : set.rest) box.extend(x);
    std::vector<uint32_t> ids(set.size());
    for (uint32_t i = 0; i < ids.size(); ++i) ids[i] = i;
    nodes.reserve(2 * set.size());
    build(set, ids, 0, ids.size(), box.center(), 0.5 * box.sizes().maxCoeff() * (1 + 1e-9), -1);
  }

  // The paper's update for a fracture of radius r at c (nearest: the phyxel nearest c).
  size_t fracture(const phyxel::PhyxelSet& set, uint32_t nearest, const Vec3& c, double r,
                  double delta) {
    int32_t top = nodes[leaf_of[nearest]].parent;
    // Up to the first ancestor whose cell holds the whole ball (the paper: larger than R).
    while (nodes[top].parent >= 0 &&
           (nodes[top].coordinate - c).cwiseAbs().maxCoeff() + r + delta > nodes[top].radius)
      top = nodes[top].parent;
    size_t deleted = 0;
    std::vector<int32_t> stack{top}, emptied;
    while (!stack.empty()) {
      const int32_t n = stack.back();
      stack.pop_back();
      for (int32_t& ch : nodes[n].child) {
        if (ch < 0) continue;
        const OctreeNode& child = nodes[ch];
        if ((child.coordinate - c).cwiseAbs().maxCoeff() > child.radius + r + delta) continue;
        if (child.phyxel < 0) {
          stack.push_back(ch);
          continue;
        }
        const double d = (set.rest[child.phyxel] - c).norm();
        if (d <= r) {
          ch = -1;  // deleted
          ++deleted;
          emptied.push_back(n);
        } else if (d <= r + delta) {
          nodes[ch].flag = 1;
        }
      }
    }
    // Parents whose leaves all went are removed, and theirs in turn.
    for (int32_t n : emptied) {
      while (n >= 0 && nodes[n].parent >= 0 &&
             std::all_of(nodes[n].child.begin(), nodes[n].child.end(),
                         [](int32_t ch) { return ch < 0; })) {
        const int32_t parent = nodes[n].parent;
        for (int32_t& ch : nodes[parent].child)
          if (ch == n) ch = -1;
        n = parent;
      }
    }
    return deleted;
  }
};

uint32_t nearest_to(const phyxel::PhyxelSet& set, const Vec3& c) {
  uint32_t best = 0;
  for (uint32_t i = 1; i < set.size(); ++i)
    if ((set.rest[i] - c).squaredNorm() < (set.rest[best] - c).squaredNorm()) best = i;
  return best;
}

void measure_octree(long size) {
  const phyxel::Scene scene = box_scene(size);
  const phyxel::PhyxelSet set = phyxel::sample_scene(scene);
  const double spacing = set.objects[0].spacing;
  const double radius = std::max(0.004, 1.5 * spacing);  // the brain scene's reach, 4 mm
  phyxel::CpuSolver<double> solver(set, Vec3::Zero());
  solver.set_threads(1);
  const phyxel::NeighbourLists& nbr = solver.neighbours();
  const int repeats = 5;
  std::vector<double> forces, cut, aspiration, build, edit;
  size_t cut_pairs = 0, removed = 0, deleted = 0, nodes = 0;
  auto time_forces = [&] {
    const double t0 = thread_micros();
    solver.compute_forces();
    forces.push_back(thread_micros() - t0);
    return forces.back();
  };
  for (int r = 0; r < repeats; ++r) {
    // A 1 cm x 1 cm patch of the plane x = x_cut (between lattice planes), fresh per repeat.
    const double x_cut = 0.02 + (r + 0.5) * 2.5 * spacing;
    std::vector<phyxel::SeveredPair> pairs;
    for (uint32_t i = 0; i < set.size(); ++i) {
      const Vec3& a = set.rest[i];
      if (a.x() > x_cut || std::abs(a.y() - 0.05) > 0.005 || std::abs(a.z() - 0.05) > 0.005)
        continue;
      for (uint32_t e = nbr.offset[i]; e < nbr.offset[i + 1]; ++e)
        if (set.rest[nbr.index[e]].x() > x_cut) pairs.push_back({i, nbr.index[e], 0.5f, false});
    }
    cut_pairs = pairs.size();
    double t0 = thread_micros();
    solver.sever_pairs(pairs);
    cut.push_back(thread_micros() - t0 - time_forces());
    // A ball at the top around a phyxel, fresh per repeat.
    const Vec3 c = set.rest[nearest_to(set, Vec3(0.015 + 0.015 * r, 0.02, 0.1))];
    std::vector<uint32_t> ball;
    for (uint32_t i = 0; i < set.size(); ++i)
      if ((set.rest[i] - c).norm() <= radius) ball.push_back(i);
    removed = ball.size();
    t0 = thread_micros();
    solver.remove_phyxels(ball);
    aspiration.push_back(thread_micros() - t0 - time_forces());
    t0 = thread_micros();
    Octree tree(set);
    build.push_back(thread_micros() - t0);
    nodes = tree.nodes.size();
    const uint32_t near = nearest_to(set, c);
    t0 = thread_micros();
    deleted = tree.fracture(set, near, c, radius, spacing);
    edit.push_back(thread_micros() - t0);
  }
  std::printf(
      "%9zu phyxels (spacing %.3g mm): forces %.0f us; cut of %zu pairs %.0f us; aspiration of "
      "%zu phyxels (R %.1f mm) %.0f us; octree of %zu nodes built in %.0f us, its fracture edit "
      "(%zu leaves) %.0f us\n",
      set.size(), spacing * 1e3, median(forces), cut_pairs, median(cut), removed, radius * 1e3,
      median(aspiration), nodes, median(build), deleted, median(edit));
}

void measure_eq23() {
  const double young = 1e4, poisson = 0.3;
  const double lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  const double mu = young / (2 * (1 + poisson));
  for (const double spacing : {0.002, 0.001}) {
    const std::string json =
        R"({"simulation": {"dt": 1e-5, "steps": 1, "gravity": [0, 0, 0]},
  "objects": [{"name": "cube", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.01, 0.01, 0.01]},
    "spacing": )" +
        std::to_string(spacing) +
        R"(, "material": {"young": 1e4, "poisson": 0.3, "density": 1000}}],
  "output": {"every": 0}})";
    const phyxel::Scene scene = phyxel::parse_scene(json, "cube.json");
    const phyxel::PhyxelSet set = phyxel::sample_scene(scene);
    phyxel::CpuSolver<double> solver(set, Vec3::Zero());
    solver.set_threads(1);
    for (size_t i = 0; i < set.size(); ++i)
      solver.displacement()[i] = Vec3(0.1 * set.rest[i].x(), 0, 0);
    solver.compute_forces();
    const uint32_t face = nearest_to(set, Vec3(0.01, 0.005, 0.005));
    const Eigen::Matrix3d g = solver.gradient(face);
    const Eigen::Matrix3d f = Eigen::Matrix3d::Identity() + g;
    const Eigen::Matrix3d eps = 0.5 * (f.transpose() * f - Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d sigma = lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
    const Eigen::Matrix3d eq23 = -set.volume[face] * sigma * g * eps;
    const Vec3 force = solver.force()[face];
    std::printf(
        "spacing %.0f mm: solver force on the face phyxel |f| = %.3e N (|f| / s^2 = %.0f Pa, "
        "sigma_xx %.0f Pa); eq 23: a 3 x 3 matrix of norm %.3e N m (v_i = %.1e m^3)\n",
        spacing * 1e3, force.norm(), force.norm() / (spacing * spacing), sigma(0, 0), eq23.norm(),
        set.volume[face]);
  }
}

// The block and descending aspirator of tests/cutting/suction_test.cpp.
const char* kSuctionBlock = R"({"simulation": {"dt": 1e-3, "steps": 300, "gravity": [0, 0, 0]},
  "objects": [{"name": "brain", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.02, 0.01]},
    "spacing": 0.002,
    "material": {"young": 5e3, "poisson": 0.3, "density": 1000, "damping": 40, "tear_stress": 1000},
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0001]}]}],
  "tools": [{"name": "aspirator", "type": "suction",
    "shape": {"type": "capsule", "radius": 0.0015, "length": 0.05},
    "path": [{"t": 0, "position": [0.01, 0.01, 0.0117], "axis": [0, 0, 1]},
             {"t": 0.3, "position": [0.01, 0.01, 0.0057], "axis": [0, 0, 1]}],
    "suction": {"pressure": 20000, "reach": 0.005, "until": 0.3}}],
  "output": {"every": 0}})";

void measure_height_field() {
  const phyxel::Scene scene = phyxel::parse_scene(kSuctionBlock, "block.json");
  const phyxel::PhyxelSet set = phyxel::sample_scene(scene);
  const double spacing = set.objects[0].spacing;
  const std::unique_ptr<phyxel::Solver> solver = phyxel::make_cpu_solver(set, Vec3::Zero(), 1);
  std::vector<uint8_t> exposed(set.size(), 0), gone(set.size(), 0);
  phyxel::RunOptions options;
  options.steps = 300;
  int events = 0;
  options.on_aspiration = [&](const phyxel::AspirationEvent& e) {
    ++events;
    for (const uint32_t i : e.removed) gone[i] = 1;
    for (const uint32_t i : e.exposed) exposed[i] = 1;
  };
  phyxel::run_simulation(scene, set, *solver, options);
  const std::vector<Vec3> u = solver->read_state(false).displacement;
  std::vector<Vec3> points;  // the tool's axis is z
  for (uint32_t i = 0; i < set.size(); ++i)
    if (exposed[i] && !gone[i]) points.push_back(set.rest[i] + u[i]);
  if (points.empty()) {
    std::printf("no fracture surface left\n");
    return;
  }
  const phyxel::Bounds2 b = phyxel::bounds_xy(points);
  const int nx = std::max(1, int(std::ceil((b.max_x - b.min_x) / spacing)));
  const int ny = std::max(1, int(std::ceil((b.max_y - b.min_y) / spacing)));
  const phyxel::HeightField field = phyxel::make_height_field(points, nx, ny);
  size_t below = 0, deep = 0;  // more than 0.5 and 1.5 spacings below their cell's height
  for (const Vec3& p : points) {
    const int i = std::clamp(int((p.x() - field.min_x) / field.cell_x), 0, nx - 1);
    const int j = std::clamp(int((p.y() - field.min_y) / field.cell_y), 0, ny - 1);
    below += p.z() < field.at(i, j) - 0.5 * spacing;
    deep += p.z() < field.at(i, j) - 1.5 * spacing;
  }
  const double n = double(points.size());
  std::printf(
      "%d aspirations, %zu fracture-surface phyxels on %d x %d cells of %.1f mm: %zu (%.0f %%) "
      "more than half a spacing below their cell's height, %zu (%.0f %%) more than 1.5\n",
      events, points.size(), nx, ny, spacing * 1e3, below, 100.0 * double(below) / n, deep,
      100.0 * double(deep) / n);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "eq23") {
    measure_eq23();
    return 0;
  }
  if (mode == "height-field") {
    measure_height_field();
    return 0;
  }
  if (mode != "octree") {
    std::fprintf(stderr, "usage: paper_measurements octree [sizes...] | eq23 | height-field\n");
    return 2;
  }
  std::vector<long> sizes;
  for (int k = 2; k < argc; ++k) sizes.push_back(std::atol(argv[k]));
  if (sizes.empty()) sizes = {10000, 100000, 1000000};
  for (const long n : sizes) {
    if (n < 8) {
      std::fprintf(stderr, "paper_measurements: a size of %ld phyxels; allowed 8 or more\n", n);
      return 2;
    }
    measure_octree(n);
  }
  return 0;
}
