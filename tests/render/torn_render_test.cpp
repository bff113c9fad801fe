// Torn faces drawn (render/cut_surfels.h, shaders/torn_tissue.glsl; docs/tearing.md), on
// lavapipe with validation: the severed box of severed_box.h with its pairs logged as torn
// (SeveredPair::torn, t = 0.5, as tearing logs them) against the same box cut. The torn face is
// closed at 1080p (the noise displaces its discs, which must still overlap), its splats carry
// the torn flag, and it looks different from the clean cut: darker, red, with clotted patches.
#include <gtest/gtest.h>

#include <cmath>

#include "render/cut_surfels.h"
#include "tests/render/severed_box.h"

namespace phyxel::render {
namespace {

class TornRender : public gpu::VulkanTest {};

struct FaceStats {
  size_t pixels = 0, background = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();  // 0..255
  size_t dark = 0;                                 // red below 40 of 255
};

FaceStats face_stats(const test::SeveredBoxFrame& frame) {
  FaceStats s;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& [x, y] : test::face_pixels(frame, 1.5 * test::kBoxSpacing)) {
    const uint8_t* c = frame.image.at(x, y);
    ++s.pixels;
    s.background += test::is_background(c);
    sum += Eigen::Vector3d(c[0], c[1], c[2]);
    s.dark += c[0] < 40;
  }
  if (s.pixels == 0) return s;
  s.mean = sum / double(s.pixels);
  return s;
}

TEST_F(TornRender, TornFaceIsClosedDarkerAndBloodierThanACleanCut) {
  const test::SeveredBoxFrame cut = test::render_severed_box(ctx(), false, "torn_render/cut");
  const test::SeveredBoxFrame torn = test::render_severed_box(ctx(), true, "torn_render/torn");
  EXPECT_EQ(torn.cut_surfels, torn.cut_faces);
  EXPECT_GT(torn.cut_faces, 200u);
  // Every cut-face splat of the torn box is torn; none of the cut box's is.
  size_t torn_splats = 0, cut_splats_torn = 0;
  for (const layout::Splat& s : torn.splats)
    torn_splats += (uint32_t(s.normal.w) & layout::kSplatTornFace) != 0;
  for (const layout::Splat& s : cut.splats)
    cut_splats_torn += (uint32_t(s.normal.w) & layout::kSplatTornFace) != 0;
  EXPECT_EQ(torn_splats, torn.cut_surfels);
  EXPECT_EQ(cut_splats_torn, 0u);

  const FaceStats c = face_stats(cut), t = face_stats(torn);
  ASSERT_GT(t.pixels, 20000u);
  EXPECT_EQ(t.background, 0u) << "background shows through the torn face";
  std::printf(
      "cut face: mean (%.0f, %.0f, %.0f), %zu dark; torn: (%.0f, %.0f, %.0f), %zu dark of %zu\n",
      c.mean.x(), c.mean.y(), c.mean.z(), c.dark, t.mean.x(), t.mean.y(), t.mean.z(), t.dark,
      t.pixels);
  // Darker than the clean cut, still red (blood-tinged: red well above green and blue).
  EXPECT_LT(t.mean.sum(), 0.8 * c.mean.sum());
  EXPECT_GT(t.mean.x(), 2.5 * t.mean.y());
  EXPECT_GT(t.mean.x(), 2.0 * t.mean.z());
  // Clotted patches: a share of the face much darker than the clean cut's mean, which the
  // cut's even fibres do not have.
  EXPECT_GT(double(t.dark), 0.08 * double(t.pixels));
  EXPECT_LT(double(c.dark), 0.02 * double(c.pixels));
  // Pixel by pixel the two differ over most of the face.
  size_t differ = 0, both = 0;
  for (const auto& [x, y] : test::face_pixels(torn, 1.5 * test::kBoxSpacing)) {
    const uint8_t *a = torn.image.at(x, y), *b = cut.image.at(x, y);
    ++both;
    differ += std::abs(int(a[0]) - int(b[0])) + std::abs(int(a[1]) - int(b[1])) +
                  std::abs(int(a[2]) - int(b[2])) >
              30;
  }
  EXPECT_GT(double(differ), 0.5 * double(both));
}

// The surfels themselves: torn faces are displaced along their normal within the amplitude,
// tilted, and larger than a cut face's; a cut face of the same phyxel is as before.
TEST_F(TornRender, TornFaceSurfelsAreDisplacedTiltedAndLarger) {
  const PhyxelSet set = test::cut_box();
  const NeighbourLists nbr = find_rest_neighbours(set);
  CutFaces cut, torn;
  cut.add(set, test::pairs_across(set, nbr, false));
  std::vector<SeveredPair> pairs = test::pairs_across(set, nbr, false);
  for (SeveredPair& p : pairs) p.torn = true;  // the same crossing points, torn
  torn.add(set, pairs);
  const double amplitude = kTornAmplitudeSpacings * test::kBoxSpacing;
  int tilted = 0, displaced = 0, faces = 0;
  for (uint32_t k = 0; k < set.size(); ++k) {
    if (cut.face(k) == nullptr) continue;
    ++faces;
    const layout::SurfelStatic a = cut_face_surfel(set, k, *cut.face(k));
    const layout::SurfelStatic b = cut_face_surfel(set, k, *torn.face(k));
    EXPECT_EQ(a.flags & layout::kSurfelTornFace, 0u);
    EXPECT_NE(b.flags & layout::kSurfelTornFace, 0u);
    EXPECT_NE(b.flags & layout::kSurfelCutFace, 0u);
    EXPECT_FLOAT_EQ(b.radius, float(kTornRadiusScale) * a.radius);
    const Vec3 na(a.normal.x, a.normal.y, a.normal.z), nb(b.normal.x, b.normal.y, b.normal.z);
    // The centre's distance along the face normal moved by at most the amplitude.
    const double along = double(b.normal.w) * na.dot(nb) - double(a.normal.w);
    EXPECT_LE(std::abs(along), amplitude * 1.0001 + 1e-9) << "phyxel " << k;
    displaced += std::abs(along) > 0.1 * amplitude;
    tilted += (nb - na).norm() > 0.05;
  }
  EXPECT_GT(faces, 200);
  EXPECT_GT(displaced, faces / 3);
  EXPECT_GT(tilted, faces / 3);
}

}  // namespace
}  // namespace phyxel::render
