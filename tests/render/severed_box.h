// The severed box of the cut-face render tests (cut_render_test.cpp, torn_render_test.cpp): a
// box severed by hand along a plane (the CPU solver's sever_pairs, as cuts or as tears), its
// halves pulled apart through the displacement, and the frame written as a run writes it
// (write_solver_frame: the cuts followed, the alive mask uploaded), at 1080p, looking at the
// right half's face.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "render/cut_surfels.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render::test {

inline constexpr double kBoxSpacing = 0.002;
// The cut: the plane n . (x - kThrough) = 0, slightly oblique to the lattice so that the cut
// face is a staircase of phyxels, as a real blade leaves it.
inline const Vec3 kCutNormal = Vec3(1, 0.2, 0.1).normalized();
inline const Vec3 kCutThrough(0.0011, 0, 0);

inline double side_of(const Vec3& x) {
  return kCutNormal.dot(x - kCutThrough);
}

// The box [-1, 1]^3 cm on a 2 mm lattice (11^3 phyxels), as a scene-less set.
inline PhyxelSet cut_box() {
  return lattice_box(Vec3(-0.01, -0.01, -0.01), Vec3(0.01, 0.01, 0.01), kBoxSpacing);
}

// Every neighbour pair whose segment crosses the plane, severed where it does; `torn`: logged
// as torn by stress (t = 0.5, as tearing logs them) instead of cut.
inline std::vector<SeveredPair> pairs_across(const PhyxelSet& set, const NeighbourLists& nbr,
                                             bool torn = false) {
  std::vector<SeveredPair> pairs;
  for (uint32_t i = 0; i < set.size(); ++i)
    for (uint32_t e = nbr.offset[i]; e < nbr.offset[i + 1]; ++e) {
      const uint32_t j = nbr.index[e];
      const double di = side_of(set.rest[i]), dj = side_of(set.rest[j]);
      if (j <= i || (di < 0) == (dj < 0)) continue;
      pairs.push_back({i, j, torn ? 0.5f : float(di / (di - dj)), torn});
    }
  return pairs;
}

// The halves apart: the left one (negative side) 4 cm along -x, out of the way; the right one
// 2 mm along +x and sheared and stretched (an affine field, which MLS reproduces exactly, so
// the right half's F is I + G wherever its own neighbours are all that count).
inline const Eigen::Matrix3d kShear =
    (Eigen::Matrix3d() << 0.10, 0.05, 0, 0, 0, 0.08, 0, 0, -0.05).finished();

inline Vec3 separated(const Vec3& x) {
  if (side_of(x) < 0) return Vec3(-0.04, 0, 0);
  return Vec3(0.002, 0, 0) + kShear * (x - kCutThrough);
}

// The right half's cut face seen from the left, ahead and above.
inline Camera face_camera() {
  const Vec3 target = kCutThrough + separated(kCutThrough);
  return camera_at(target + 0.08 * Vec3(-1, 0.5, 0.4).normalized(), target, Vec3::UnitZ(), 40);
}

struct SeveredBoxFrame {
  RgbaImage image;
  EyeView eye;
  size_t cut_faces = 0;      // the writer's CutFaces
  uint32_t cut_surfels = 0;  // the renderer's cut-face surfels
  std::vector<layout::Splat> splats;
};

// The severed box (torn or cut) written as frame 0 to $PHYXEL_TEST_OUT/<dir_name>.
inline SeveredBoxFrame render_severed_box(gpu::Context& ctx, bool torn,
                                          const std::string& dir_name) {
  const PhyxelSet set = cut_box();
  std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  const std::vector<SeveredPair> pairs = pairs_across(set, solver->neighbours(), torn);
  EXPECT_GT(pairs.size(), 500u);
  Cutting& cutting = *solver->cutting();
  cutting.sever_pairs(pairs);
  EXPECT_EQ(cutting.severed_pairs(), pairs.size());
  std::vector<Vec3> u(set.size());
  for (size_t i = 0; i < set.size(); ++i) u[i] = separated(set.rest[i]);
  solver->set_state(u, std::vector<Vec3>(set.size(), Vec3::Zero()));

  Scene scene;
  scene.render.width = 1920;
  scene.render.height = 1080;
  const Camera camera = face_camera();
  scene.camera.position = camera.position;
  scene.camera.target = camera.target;
  scene.camera.up = Vec3::UnitZ();
  scene.camera.fov_y_deg = 40;
  scene.camera.near = 0.01;
  scene.camera.far = 2;
  const std::filesystem::path dir = test_out_dir() / dir_name;
  std::filesystem::create_directories(dir);
  FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, dir}, &ctx);
  // As write_solver_frame does: the faces follow the solver's log, torn flags included.
  writer.set_tools({});
  writer.follow_cuts(*solver, true);
  for (const SeveredPair& p : cutting.severed_since(0)) EXPECT_EQ(p.torn, torn);
  const std::string name =
      writer.write(0, solver->read_state(false).displacement, solver->neighbours());
  std::printf("%s frame: %s\n", torn ? "torn face" : "cut face", (dir / name).c_str());
  SeveredBoxFrame out;
  writer.flush();  // frames are written on a thread of their own
  out.image = load_image(dir / name, "severed box frame");
  out.eye = writer.setup().eyes[0];
  out.cut_faces = writer.cut_faces().size();
  out.cut_surfels = writer.renderer().cut_surfel_count();
  out.splats = writer.renderer().read_splats();
  return out;
}

// The pixels of the right half's face `in` (m) in from its rim, projected.
inline std::vector<std::pair<uint32_t, uint32_t>> face_pixels(const SeveredBoxFrame& frame,
                                                              double in) {
  const uint32_t w = frame.image.width, h = frame.image.height;
  auto pixel_of = [&](double y, double z) {
    Vec3 x(0, y, z);  // on the plane at (y, z)
    x.x() = kCutThrough.x() - (kCutNormal.y() * y + kCutNormal.z() * z) / kCutNormal.x();
    return Eigen::Vector2d(
        project_to_pixel(frame.eye, x + separated(x + 1e-9 * kCutNormal), w, h).head<2>());
  };
  const double a = 0.01 - in;
  const std::array<Eigen::Vector2d, 4> quad = {pixel_of(-a, -a), pixel_of(a, -a), pixel_of(a, a),
                                               pixel_of(-a, a)};
  std::vector<std::pair<uint32_t, uint32_t>> out;
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      bool inside = true;
      for (int k = 0; k < 4 && inside; ++k) {
        const Eigen::Vector2d p = quad[k], q = quad[(k + 1) % 4];
        inside = (q - p).x() * (y + 0.5 - p.y()) - (q - p).y() * (x + 0.5 - p.x()) >= 0;
      }
      if (inside) out.emplace_back(x, y);
    }
  return out;
}

}  // namespace phyxel::render::test
