// Cut faces drawn (render/cut_surfels.h, SplatRenderer::update_cut_surfels), on lavapipe with
// validation: the severed box of severed_box.h, its pairs cut. The right half's cut face
// is closed at 1080p and shows cut tissue, not the outer surface's texture; the deform pass
// skips the severed pairs exactly as its CPU twin does.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <array>
#include <cmath>

#include "engine/solver/mls_gradient.h"
#include "render/cut_surfels.h"
#include "tests/render/severed_box.h"

namespace phyxel::render {
namespace {

class CutRender : public gpu::VulkanTest {};

using test::cut_box;
using test::kBoxSpacing;
using test::kShear;
using test::pairs_across;
using test::separated;
using test::side_of;

// The CPU twin of deform_surfels.comp in double (engine/solver/mls_gradient.h): centre and
// normal of a surfel from the alive pairs only (alive null: every pair).
layout::Splat cpu_deform(const PhyxelSet& set, const NeighbourLists& nbr,
                         const std::vector<uint8_t>* alive, const std::vector<Vec3>& u,
                         const layout::SurfelStatic& s) {
  const uint32_t i = s.index;
  const Eigen::Matrix3d f =
      mls_deformation(set.rest, nbr, u, i, s.support, [&](uint32_t e, uint32_t) {
        return alive == nullptr || (*alive)[e] != 0;
      }).f;
  const Vec3 n0(s.normal.x, s.normal.y, s.normal.z);
  const Vec3 n = (f.inverse().transpose() * n0).normalized();
  const bool cut = (s.flags & layout::kSurfelCutFace) != 0;
  const Vec3 c = set.rest[i] + u[i] + (cut ? Vec3(f * n0 * double(s.normal.w)) : Vec3::Zero());
  layout::Splat out{};
  out.centre = {float(c.x()), float(c.y()), float(c.z()), 0};
  out.normal = {float(n.x()), float(n.y()), float(n.z()), 0};
  return out;
}

bool cut_coloured(const uint8_t* p) {
  return p[0] > 60 && p[1] < 0.4 * p[0] && p[2] < 0.5 * p[0];
}

TEST_F(CutRender, SeveredBoxShowsAClosedCutFaceOfCutTissue) {
  const test::SeveredBoxFrame frame = test::render_severed_box(ctx(), false, "cut_render");
  const RgbaImage& image = frame.image;
  const uint32_t w = image.width, h = image.height;
  const EyeView& eye = frame.eye;
  // The cuts were followed: one face per phyxel on either side of the plane.
  EXPECT_EQ(frame.cut_surfels, frame.cut_faces);
  EXPECT_GT(frame.cut_faces, 200u);

  // The inner part of the right half's face (1.5 spacings in from its rim).
  size_t region = 0, background = 0, cut = 0;
  for (const auto& [x, y] : test::face_pixels(frame, 1.5 * kBoxSpacing)) {
    ++region;
    background += test::is_background(image.at(x, y));
    cut += cut_coloured(image.at(x, y));
  }
  ASSERT_GT(region, 20000u) << "the face is large in the frame (orientation of the quad?)";
  EXPECT_EQ(background, 0u) << "background shows through the cut face";
  EXPECT_GT(double(cut), 0.97 * double(region)) << "cut tissue over the face";

  // The outer surface next to it (the right half's top, z = 1 cm) is the texture's pale pink.
  // (From here the top is seen at a grazing angle: the cut face's rim discs, which overhang the
  // edge by up to 0.6 spacing, cover the top's first 6 mm in the image.)
  // Its vessels are a dark red as well, so the test is on the mean over a patch around each
  // point: pale pink (green at half the red), and only where a vessel passes cut-coloured.
  size_t outer = 0, outer_cut = 0;
  double red = 0, green = 0;
  for (double a = 0.007; a <= 0.0091; a += 0.001)
    for (double b = -0.006; b <= 0.0061; b += 0.002) {
      const Vec3 x(a, b, 0.01);
      const Eigen::Vector3d p = project_to_pixel(eye, x + separated(x), w, h);
      for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
          const uint8_t* c = image.at(uint32_t(p.x() + dx), uint32_t(p.y() + dy));
          ++outer;
          outer_cut += cut_coloured(c);
          red += c[0];
          green += c[1];
        }
    }
  EXPECT_GT(green, 0.5 * red) << "the outer surface's mean colour";
  EXPECT_LT(double(outer_cut), 0.1 * double(outer)) << "of " << outer << " outer-surface pixels";
  std::printf(
      "cut face: %zu pixels, %zu cut-coloured; outer surface: green / red %.2f, %zu of "
      "%zu cut-coloured\n",
      region, cut, green / red, outer_cut, outer);
}

TEST_F(CutRender, DeformPassSkipsSeveredPairsAsItsCpuTwin) {
  const PhyxelSet set = cut_box();
  std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  const NeighbourLists& nbr = solver->neighbours();
  Cutting& cutting = *solver->cutting();
  cutting.sever_pairs(pairs_across(set, nbr));
  const std::vector<uint8_t> alive = cutting.pair_alive();
  std::vector<Vec3> u(set.size());
  for (size_t i = 0; i < set.size(); ++i) u[i] = separated(set.rest[i]);

  HostInputs inputs(ctx(), set, nbr);
  SplatRenderer renderer(ctx(), build_surfel_table(set), procedural_tissue_texture(64));
  CutFaces faces;
  faces.add(set, cutting.severed_since(0));
  const std::vector<layout::SurfelStatic> cut = cut_face_surfels(set, faces, faces.take_changed());
  renderer.update_cut_surfels(cut);
  inputs.set_displacement(u);
  const FrameSetup setup = test::setup_for(test::face_camera(), 64, 36);
  auto splats_with = [&](bool mask) {
    if (mask) inputs.set_pair_alive(alive);
    renderer.render(inputs.inputs(), setup);
    return renderer.read_splats();
  };
  const std::vector<layout::Splat> unmasked = splats_with(false);
  const std::vector<layout::Splat> masked = splats_with(true);
  std::vector<layout::SurfelStatic> surfels = build_surfel_table(set).surfels;
  surfels.insert(surfels.end(), cut.begin(), cut.end());
  ASSERT_EQ(masked.size(), surfels.size());

  // Next to the cut (within the support radius of the plane) the masked splats are their CPU
  // twin's with the alive pairs; without the mask they are far from it (the halves' relative
  // motion entered grad u).
  double worst_normal = 0, worst_centre = 0, unmasked_off = 0;
  int near = 0;
  for (size_t k = 0; k < surfels.size(); ++k) {
    const layout::SurfelStatic& s = surfels[k];
    if (std::abs(side_of(set.rest[s.index])) > 2 * kBoxSpacing) continue;
    ++near;
    const layout::Splat want = cpu_deform(set, nbr, &alive, u, s);
    auto vec = [](const layout::vec4& v) { return Vec3(v.x, v.y, v.z); };
    worst_normal = std::max(worst_normal, (vec(masked[k].normal) - vec(want.normal)).norm());
    worst_centre = std::max(worst_centre, (vec(masked[k].centre) - vec(want.centre)).norm());
    unmasked_off = std::max(unmasked_off, (vec(unmasked[k].normal) - vec(want.normal)).norm());
    const bool is_cut = (uint32_t(masked[k].normal.w) & layout::kSplatCutFace) != 0;
    EXPECT_EQ(is_cut, (s.flags & layout::kSurfelCutFace) != 0) << "splat " << k;
  }
  EXPECT_GT(near, 200);
  EXPECT_LT(worst_normal, 1e-4);
  EXPECT_LT(worst_centre, 1e-6) << "m";
  EXPECT_GT(unmasked_off, 0.1) << "the test tells masked from unmasked";
  // On the right half F = I + kShear: a cut face's normal is (I + G)^-T n on the twin's side too.
  for (size_t k = 0; k < cut.size(); ++k) {
    const layout::SurfelStatic& s = cut[k];
    if (side_of(set.rest[s.index]) < 0 || !faces.face(s.index)->fitted) continue;
    const Vec3 n0(s.normal.x, s.normal.y, s.normal.z);
    const Vec3 expected =
        ((Eigen::Matrix3d::Identity() + kShear).inverse().transpose() * n0).normalized();
    const layout::vec4& got = masked[surfels.size() - cut.size() + k].normal;
    EXPECT_LT((Vec3(got.x, got.y, got.z) - expected).norm(), 1e-3) << "phyxel " << s.index;
  }
}

// A cut that leaves a surface phyxel only the neighbours of its own layer (A singular across
// the layer) or one more just off it (A far beyond the condition limit): the deform pass
// draws the normal and texture gradients of the solver's regularised gradient there, not the
// rest normal and not the exact inverse's.
TEST_F(CutRender, DeformPassUsesTheSolversGradientNextToACut) {
  PhyxelSet set = cut_box();
  const double s = kBoxSpacing;
  auto at = [&](int x, int y, int z) {  // the lattice phyxel at (x, y, z) spacings
    for (uint32_t i = 0; i < set.size(); ++i)
      if ((set.rest[i] - Vec3(x, y, z) * s).norm() < 1e-3 * s) return i;
    ADD_FAILURE() << "no phyxel at " << x << " " << y << " " << z;
    return 0u;
  };
  const uint32_t flat = at(-2, 0, 5), lone = at(2, 0, 5), off = at(3, 1, 4);
  set.rest[off].z() += 0.9 * s;  // lone's one neighbour below, nearly in its layer
  CpuSolver<double> solver(set, Vec3::Zero());
  const NeighbourLists& nbr = solver.neighbours();
  std::vector<SeveredPair> cut;
  for (const uint32_t i : {flat, lone})
    for (uint32_t e = nbr.offset[i]; e < nbr.offset[i + 1]; ++e) {
      const uint32_t j = nbr.index[e];
      if (set.rest[j].z() < set.rest[i].z() - 1e-3 * s && j != off)
        cut.push_back({std::min(i, j), std::max(i, j), 0.5f, false});
    }
  solver.sever_pairs(cut);
  // A curved field: u_z = a x^2 + b x y bends the top, plus an in-plane shear and stretch.
  std::vector<Vec3>& u = solver.displacement();
  for (size_t i = 0; i < set.size(); ++i) {
    const Vec3 x = set.rest[i] / 0.01;
    u[i] = 0.002 * Vec3(0.3 * x.x() + 0.2 * x.y() * x.z(), 0.1 * x.x() * x.z(),
                        1.2 * x.x() * x.x() + 0.5 * x.x() * x.y());
  }
  std::vector<uint8_t> alive(nbr.index.size());
  for (size_t e = 0; e < alive.size(); ++e) alive[e] = solver.pair_weights()[e] != 0;

  HostInputs inputs(ctx(), set, nbr);
  const SurfelTable table = build_surfel_table(set);
  SplatRenderer renderer(ctx(), table, procedural_tissue_texture(64));
  inputs.set_displacement(u);
  inputs.set_pair_alive(alive);
  renderer.render(inputs.inputs(), test::setup_for(test::face_camera(), 64, 36));
  const std::vector<layout::Splat> splats = renderer.read_splats();
  auto vec = [](const layout::vec4& v) { return Vec3(v.x, v.y, v.z); };
  for (const uint32_t i : {flat, lone}) {
    size_t k = 0;
    while (k < table.surfels.size() && table.surfels[k].index != i) ++k;
    ASSERT_LT(k, table.surfels.size()) << "phyxel " << i << " has a surfel";
    const layout::SurfelStatic& surfel = table.surfels[k];
    // The solver's own A: regularised, singular (flat) or nearly so (lone).
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    for (uint32_t e = nbr.offset[i]; e < nbr.offset[i + 1]; ++e) {
      const Vec3 x = set.rest[nbr.index[e]] - set.rest[i];
      a += solver.pair_weights()[e] * x * x.transpose();
    }
    EXPECT_GT(regularised_inverse(a).condition, 5 * kMaxMomentCondition) << "phyxel " << i;
    const Eigen::Matrix3d f_inv_t =
        (Eigen::Matrix3d::Identity() + solver.gradient(i)).inverse().transpose();
    const Vec3 n0 = vec(surfel.normal);
    const Vec3 want_n = (f_inv_t * n0).normalized();
    EXPECT_GT((want_n - n0).norm(), 0.1) << "the bend tilts the normal";
    EXPECT_LT((vec(splats[k].normal) - want_n).norm(), 1e-3) << "phyxel " << i;
    EXPECT_LT((vec(splats[k].ds_dx) - f_inv_t * vec(surfel.ds_dx)).norm(),
              1e-3 * vec(surfel.ds_dx).norm())
        << "phyxel " << i;
    EXPECT_LT((vec(splats[k].dt_dx) - f_inv_t * vec(surfel.dt_dx)).norm(),
              1e-3 * vec(surfel.dt_dx).norm())
        << "phyxel " << i;
  }
}

}  // namespace
}  // namespace phyxel::render
