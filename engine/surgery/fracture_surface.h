// The rough look of a fracture surface (the paper's section V.B-C, eqs 27-30, and what the
// renderer does instead; docs/tearing.md, docs/decisions.md). Pure CPU, deterministic.
//
// Noise. Seeded gradient (Perlin) noise in 2-D and 3-D: a permutation of 0..255 shuffled by
// Fisher-Yates with SplitMix64 from the seed (integer arithmetic only, so the permutation is
// the same on every platform; no std::*_distribution, whose output is implementation-defined),
// unit gradients from fixed tables, Perlin's quintic fade. Each octave is normalised by the
// largest value gradient noise with unit gradients can take (sqrt(D)/2 in D dimensions) and
// clamped to [-1, 1]; octaves double the frequency and multiply the weight by `persistence`,
// and the sum is divided by the sum of the weights, so |fbm| <= amplitude always.
//
// The paper's method (kept, tested, and usable where a fracture is a height field):
//   noise plane   a square of ro x co cells whose (ro+1) x (co+1) corners carry noise values;
//                 the centre (ro/2, co/2) is the paper's; values farther than 0.9 R from it are
//                 0 and those between Ri = 0.5 R and Ro = 0.9 R are scaled by eq 27,
//                 1 - (d - Ri) / (Ro - Ri). R and d are in grid cells: R is the fracture radius
//                 mapped onto the plane by eqs 28-29. When the plane spans the fracture's
//                 bounding square (the sphere's outline, 2 R across), R = co / 2 cells.
//   eqs 28-29     a fracture point's (x, y) mapped linearly from the fracture surface's bounds
//                 to the plane's bounds; eq 30 adds the plane's value there (bilinear) to z.
//   height field  the fracture points projected on a grid of cells over their (x, y) bounds;
//                 each cell's height is the largest z projected into it (the smallest z of all
//                 points where none is), carried by the cell's lower-left corner; each square
//                 of four neighbouring corners is drawn as two triangles.
//
// What the renderer uses (works for any shape): the displacement of a surfel along its own
// normal by 3-D noise at its rest position, scaled by the same ring falloff (eq 27) of its
// distance from the fracture's axis, with the normal tilted by the displacement's gradient
// (the normal of the displaced surface), so a curved or deep tear is rough everywhere without
// a projection plane and without re-triangulation.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace phyxel {

using Vec3 = Eigen::Vector3d;

// Octave noise parameters. `frequency` is in lattice cells per unit of the input coordinates
// (per grid cell for the noise plane, per metre for 3-D noise at rest positions); `amplitude`
// bounds the result (grid height units, metres for surfel displacements).
struct NoiseParams {
  uint64_t seed = 1;
  double frequency = 1;
  double amplitude = 1;
  int octaves = 1;           // >= 1
  double persistence = 0.5;  // weight ratio of each octave to the previous one
};

// Seeded gradient noise, one octave, values in [-1, 1] (see above).
class PerlinNoise {
 public:
  explicit PerlinNoise(uint64_t seed);

  double noise2(double x, double y) const;
  double noise3(const Vec3& p) const;
  // noise3 and its exact gradient (of the unclamped value).
  double noise3(const Vec3& p, Vec3* gradient) const;

  // The permutation (for tests of determinism): perm()[k] for k in 0..255.
  const std::array<uint8_t, 256>& perm() const { return perm_; }

 private:
  uint8_t hash(int x) const { return perm_[static_cast<uint32_t>(x) & 255u]; }
  std::array<uint8_t, 256> perm_;
};

// Octave sums (fractal Brownian motion) with |result| <= params.amplitude.
double fbm2(const NoiseParams& params, double x, double y);
double fbm3(const NoiseParams& params, const Vec3& p, Vec3* gradient = nullptr);

// Eq 27's factor at distance d from the centre of a fracture of radius R (any one unit):
// 1 for d <= Ri = 0.5 R, 1 - (d - Ri) / (Ro - Ri) up to Ro = 0.9 R, 0 beyond.
inline constexpr double kRingInner = 0.5;  // Ri / R
inline constexpr double kRingOuter = 0.9;  // Ro / R
double ring_falloff(double d, double radius);

// The paper's noise plane: (rows + 1) x (cols + 1) corner values, row-major.
struct NoisePlane {
  int rows = 0, cols = 0;  // cells
  std::vector<double> value;

  double at(int row, int col) const { return value[size_t(row) * size_t(cols + 1) + size_t(col)]; }
  // Bilinear value at plane coordinates X (along the columns, [0, cols]) and Y (along the
  // rows, [0, rows]); clamped to the plane outside it.
  double sample(double x, double y) const;
};

// fbm2 at every corner (col, row), times eq 27's factor of its distance (in cells) from the
// centre (cols / 2, rows / 2) for a fracture radius of `radius` cells. Throws
// std::invalid_argument for rows or cols < 1 or radius <= 0.
NoisePlane make_noise_plane(const NoiseParams& params, int rows, int cols, double radius);

// Axis-aligned bounds in a plane.
struct Bounds2 {
  double min_x = 0, max_x = 0, min_y = 0, max_y = 0;
};
Bounds2 bounds_xy(const std::vector<Vec3>& points);  // of the points' x and y
Bounds2 plane_bounds(const NoisePlane& plane);       // [0, cols] x [0, rows]

// Eqs 28-29: (x, y) within `surface` mapped to the plane's (X, Y) within `plane`. A surface
// bound of zero extent maps to the middle of the plane's range.
Eigen::Vector2d map_to_plane(double x, double y, const Bounds2& surface, const Bounds2& plane);

// Eq 30 for every point: z + f(X, Y), (X, Y) from eqs 28-29 with the points' own bounds.
std::vector<Vec3> disturb_fracture_points(const std::vector<Vec3>& points, const NoisePlane& plane);

// The paper's height field over the points' (x, y) bounds, nx x ny cells.
struct HeightField {
  int nx = 0, ny = 0;
  double min_x = 0, min_y = 0, cell_x = 0, cell_y = 0;  // cell (i, j) starts at min + (i, j) cell
  std::vector<double> height;                           // nx x ny, row-major (j rows)

  double at(int i, int j) const { return height[size_t(j) * size_t(nx) + size_t(i)]; }
  // The corner carrying cell (i, j)'s height: its lower-left corner at that height.
  Vec3 corner(int i, int j) const;
  // Two triangles per square of four neighbouring corners (A = (i, j+1), B = (i+1, j+1),
  // C = (i+1, j), D = (i, j): ABD and BCD, counter-clockwise seen from +z), as corners.
  std::vector<std::array<Vec3, 3>> triangles() const;
};
// Throws std::invalid_argument for nx or ny < 1 or no points.
HeightField make_height_field(const std::vector<Vec3>& points, int nx, int ny);

// The renderer's variant: where a fracture surface is rough.
//   sphere  a suction fracture: centre c, radius R, and the axis along which the tool came
//           in (unit); d is the distance from the axis through c (the paper's d, measured in
//           its projection plane, lifted to 3-D). A zero axis measures d from c itself.
//   none    radius 0: no falloff (a torn pair face: rough everywhere on the face).
struct FractureRegion {
  Vec3 centre = Vec3::Zero();
  double radius = 0;  // m; 0: no falloff
  Vec3 axis = Vec3::Zero();
};

// A surfel's displacement along its normal and its tilted normal.
struct RoughSurfel {
  double displacement = 0;      // m, along the rest normal, |.| <= params.amplitude
  Vec3 normal = Vec3::UnitZ();  // unit: the displaced surface's normal there
  double falloff = 1;           // eq 27's factor used
};

// h(x) = falloff(d(x)) fbm3(x); the normal of the surface x + h(x) n, n - grad_t h,
// normalised (grad_t: the part of grad h perpendicular to n). `x` is the rest position,
// `normal` the rest unit normal.
RoughSurfel rough_surfel(const NoiseParams& params, const FractureRegion& region, const Vec3& x,
                         const Vec3& normal);

}  // namespace phyxel
