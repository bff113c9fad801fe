// Smoothed gradients of a phyxel's cell (stabilised conforming nodal integration, Chen et al.
// 2001, with Wang & Chen's sub-domains): the integration of the "SCNI band" round a blade's cut
// (docs/cutting.md, "Stiffness of a cut body"), shared by the CPU solver's band
// (cpu_solver_band.cpp) and tools/slit_static_solve.
//
// A cell (the phyxel's lattice cell, clipped to its object) is split into `subcells`^3 boxes.
// Each box's gradient is the linear-basis MLS displacement times the outward normal integrated
// over its faces (`face_points`^2 Gauss points a face) over its volume: G_b = sum_j u_j c_bj^T
// (G_rc = d u_r / d x_c). The MLS fit at a point takes the phyxels within h, each with the weight
// a PairWeight keeps (the visibility criterion: 0 where the line of sight crosses the cut).
// Faces marked clamped take the displacement 0 (a wall the body is held on), not the fit.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "engine/geometry/vec3.h"

namespace phyxel {

// The phyxels by grid cell of size h, for the ones within h of any point.
class PointGrid {
 public:
  PointGrid(const std::vector<Vec3>& points, double h);
  // Indices within h of x (strictly inside the kernel's support), in ascending order.
  std::vector<uint32_t> within(const Vec3& x) const;

 private:
  int64_t key(const Vec3& x) const;
  static int64_t key(int64_t a, int64_t b, int64_t c);
  const std::vector<Vec3>& points_;
  double h_;
  std::unordered_map<int64_t, std::vector<uint32_t>> cells_;
};

// The weight the fit at `from` gives phyxel j, w0 its kernel weight (w0 when nothing blocks it).
// `from` is the Gauss point moved a hair towards the cell's phyxel, so a point on a cut that runs
// along the cell's face looks from the cell's side.
using PairWeight = std::function<double(const Vec3& from, uint32_t j, double w0)>;

// The linear-basis MLS shape functions at x: (phyxel, phi_j) for the phyxels within h.
std::vector<std::pair<uint32_t, double>> mls_shape_functions(const std::vector<Vec3>& rest,
                                                             const PointGrid& grid, double h,
                                                             const Vec3& x, const Vec3& from,
                                                             const PairWeight& weight);

struct ScniCell {
  Vec3 owner = Vec3::Zero();  // the cell's phyxel (the side its faces look from)
  Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();
  int subcells = 2;     // boxes per direction
  int face_points = 2;  // Gauss points per face and direction (1 or 2)
  // clamped[2 axis + side]: the face at lo[axis] (side 0) or hi[axis] (side 1) takes u = 0.
  std::array<bool, 6> clamped{};
};

// One box's smoothed gradient: G = sum_k u_node[k] coeff[k]^T, over its geometric volume.
struct ScniBox {
  double volume = 0;
  std::vector<uint32_t> node;  // ascending
  std::vector<Vec3> coeff;
};

std::vector<ScniBox> scni_boxes(const std::vector<Vec3>& rest, const PointGrid& grid, double h,
                                const ScniCell& cell, const PairWeight& weight);

// The cell of phyxel x on a lattice of the given spacing, clipped to [lo, hi].
ScniCell lattice_cell(const Vec3& x, double spacing, const Vec3& lo, const Vec3& hi);

// Distance from x to the quad's two triangles (p0 p1 p2, p0 p2 p3).
double distance_to_quad(const Vec3& x, const std::array<Vec3, 4>& quad);

}  // namespace phyxel
