// The compute splat passes against a CPU twin and their own invariants, on lavapipe with
// validation: which pixels a disc covers (the ray-disc test of every pixel, in double), in each
// of the rasteriser's three paths (a splat's own invocation, the whole workgroup for a large
// splat, the whole eye for a disc crossing the near plane); an image that does not depend on
// the order of the surfels; the texture's level of detail; frames too large for the device;
// the same image from 64-bit atomics on pairs of channels as from 32-bit ones; weight sums
// past a signed int's range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "render/environment_map.h"
#include "render/sample_shapes.h"
#include "render/tool_raycast.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

class SplatRaster : public gpu::VulkanTest {};

RgbaImage white_texture() {
  RgbaImage t(1, 1);
  t.pixels = {255, 255, 255, 255};
  return t;
}

struct Disc {
  Vec3 centre;
  Vec3 normal;
  double radius;
};

// One phyxel without neighbours (so the deform pass keeps its rest normal and radius) drawn
// as `copies` coincident discs, radius_scale 1, `frames` times by one renderer.
std::vector<RgbaImage> render_discs(gpu::Context& ctx, const Disc& d, const FrameSetup& setup,
                                    size_t copies, int frames) {
  PhyxelSet set;
  set.rest = {d.centre};
  set.volume = {1e-9};
  NeighbourLists none;
  none.offset = {0, 0};
  SurfelTable table;
  table.phyxels = 1;
  layout::SurfelStatic s{};
  s.index = 0;
  s.radius = static_cast<float>(d.radius);
  s.support = static_cast<float>(2 * d.radius);
  const Vec3 n = d.normal.normalized();
  s.normal = {float(n.x()), float(n.y()), float(n.z()), 0};
  s.ds_dx = {0, 0, 0, 0.5f};
  s.dt_dx = {0, 0, 0, 0.5f};
  table.surfels.assign(copies, s);
  table.bounds.extend(d.centre);
  HostInputs inputs(ctx, set, none);
  RendererOptions options;
  options.radius_scale = 1.0f;
  SplatRenderer renderer(ctx, table, white_texture(), options);
  std::vector<RgbaImage> images;
  for (int f = 0; f < frames; ++f) images.push_back(renderer.render(inputs.inputs(), setup));
  return images;
}

RgbaImage render_disc(gpu::Context& ctx, const Disc& d, const FrameSetup& setup) {
  return render_discs(ctx, d, setup, 1, 1).front();
}

// +1: the pixel's ray meets the disc between near and far; -1: it misses; 0: too close to the
// rim or the near/far planes to tell in float.
int cpu_coverage(const EyeView& eye, const Disc& d, uint32_t x, uint32_t y, uint32_t w,
                 uint32_t h) {
  const Frustum& f = eye.frustum;
  const Vec3 dir(f.left + (x + 0.5) / w * (f.right - f.left),
                 f.top + (y + 0.5) / h * (f.bottom - f.top), -f.near);
  const Vec3 c = (eye.view * d.centre.homogeneous()).head<3>();
  const Vec3 n = eye.view.topLeftCorner<3, 3>() * d.normal.normalized();
  const double dn = dir.dot(n);
  if (std::abs(dn) < 1e-6 * dir.norm()) return 0;
  const double t = c.dot(n) / dn;
  const Vec3 p = t * dir;
  const double q2 = (p - c).squaredNorm() / (d.radius * d.radius);
  const double depth = (-p.z() - f.near) / (f.far - f.near);
  if (t <= 0) return -1;
  if (std::abs(q2 - 1) < 1e-3 || std::abs(depth) < 1e-5 || std::abs(depth - 1) < 1e-5) return 0;
  return q2 < 1 && depth > 0 && depth < 1 ? 1 : -1;
}

struct Coverage {
  int covered = 0, mismatched = 0;
};

Coverage compare_coverage(const RgbaImage& image, const FrameSetup& setup, const Disc& d) {
  Coverage c;
  for (uint32_t y = 0; y < setup.height; ++y)
    for (uint32_t x = 0; x < setup.eye_width; ++x) {
      const int expected = cpu_coverage(setup.eyes[0], d, x, y, setup.eye_width, setup.height);
      const bool drawn = !test::is_background(image.at(x, y));
      c.covered += drawn;
      if (expected != 0 && drawn != (expected > 0)) ++c.mismatched;
    }
  return c;
}

TEST_F(SplatRaster, DiscsCoverExactlyThePixelsTheirRaysHitInEveryPath) {
  const Camera cam = test::camera_at(Vec3(0, 0, 0.1), Vec3::Zero(), Vec3::UnitY(), 40);
  const FrameSetup setup = test::setup_for(cam, 128, 96);
  const double pixel = 2 * 0.1 * std::tan(20 * M_PI / 180) / 96;  // at the target, m
  struct Case {
    const char* name;
    Disc disc;
    int min_pixels, max_pixels;
  };
  const Case cases[] = {
      // Bounds of at most kOwnPixels: drawn by the splat's own invocation.
      {"small, facing", {Vec3(0.001, 0.0005, 0), Vec3(0, 0, 1), 2.2 * pixel}, 10, 30},
      {"small, oblique", {Vec3(-0.004, 0.002, 0), Vec3(1, 0.3, 0.4), 3.0 * pixel}, 5, 30},
      // Larger: queued and drawn by the whole workgroup.
      {"large, facing", {Vec3(0, 0, 0), Vec3(0, 0, 1), 20 * pixel}, 1000, 1400},
      {"large, nearly edge-on",
       {Vec3(0.003, -0.002, 0.01), Vec3(1, 0.3, 0.12), 25 * pixel},
       50,
       600},
      {"large, off the left edge", {Vec3(-0.035, 0.01, 0), Vec3(0.2, 0, 1), 30 * pixel}, 300, 2800},
      // Crossing the near plane (0.01 from the eye): bounds are the whole eye.
      {"crossing the near plane", {Vec3(0, 0, 0.085), Vec3(0, 1, 1), 0.012}, 500, 12288},
      // Wholly nearer than the near plane, and behind the eye: nothing.
      {"before the near plane", {Vec3(0, 0, 0.095), Vec3(0, 0, 1), 0.002}, 0, 0},
      {"behind the eye", {Vec3(0, 0, 0.2), Vec3(0, 0, 1), 0.01}, 0, 0},
  };
  for (const Case& c : cases) {
    const RgbaImage image = render_disc(ctx(), c.disc, setup);
    const Coverage cov = compare_coverage(image, setup, c.disc);
    EXPECT_EQ(cov.mismatched, 0) << c.name;
    EXPECT_GE(cov.covered, c.min_pixels) << c.name;
    EXPECT_LE(cov.covered, c.max_pixels) << c.name;
    if (cov.mismatched > 0) write_png(test::test_out_dir() / "disc_coverage.png", image);
  }
}

TEST_F(SplatRaster, TheImageDoesNotDependOnTheOrderOfTheSurfels) {
  // Overlapping splats from two sides of a sphere, stereo: the accumulation is in integers,
  // so any order of the table gives the same bits.
  const PhyxelSet set = lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006);
  const NeighbourLists neighbours = find_rest_neighbours(set);
  SurfelTable table = build_surfel_table(set);
  HostInputs inputs(ctx(), set, neighbours);
  const Camera cam = test::camera_at(Vec3(0.03, -0.05, 0.03), Vec3::Zero(), Vec3::UnitZ(), 40);
  StereoSettings st;
  st.ipd = 0.01;
  const FrameSetup setup = test::setup_for(cam, 96, 80, RenderSettings::Mode::Stereo, st);
  std::vector<Vec3> u(set.size());
  for (size_t i = 0; i < u.size(); ++i) u[i] = 0.1 * set.rest[i].x() * Vec3(0, 0.3, 1);
  inputs.set_displacement(u);
  const RgbaImage reference =
      SplatRenderer(ctx(), table, procedural_tissue_texture(64)).render(inputs.inputs(), setup);
  std::mt19937 rng(7);
  std::shuffle(table.surfels.begin(), table.surfels.end(), rng);
  const RgbaImage shuffled =
      SplatRenderer(ctx(), table, procedural_tissue_texture(64)).render(inputs.inputs(), setup);
  ASSERT_EQ(shuffled.pixels.size(), reference.pixels.size());
  EXPECT_TRUE(shuffled.pixels == reference.pixels);
  int covered = 0;
  for (uint32_t y = 0; y < reference.height; ++y)
    for (uint32_t x = 0; x < reference.width; ++x)
      covered += !test::is_background(reference.at(x, y));
  EXPECT_GT(covered, 1000);
}

TEST_F(SplatRaster, AFarCheckerboardIsSampledAtItsCoarseLevelNotAliased) {
  // A flat 64 x 64 mm sheet with a 1-texel black-and-white checkerboard of 256 x 256 texels,
  // seen from afar: about 5 texels per pixel, so the texture's level of detail must come from
  // the change of (s, t) between pixels. Aliased sampling (level 0) gives pixels of either
  // colour; the right level gives the mean grey in each.
  PhyxelSet sheet = lattice_box(Vec3(-0.032, -0.032, 0), Vec3(0.032, 0.032, 0), 0.002);
  const NeighbourLists neighbours = find_rest_neighbours(sheet);
  const SurfelTable table = build_surfel_table(sheet);
  HostInputs inputs(ctx(), sheet, neighbours);
  RgbaImage checker(256, 256);
  for (uint32_t y = 0; y < 256; ++y)
    for (uint32_t x = 0; x < 256; ++x) {
      uint8_t* p = checker.at(x, y);
      p[0] = p[1] = p[2] = ((x + y) % 2) ? 255 : 0;
      p[3] = 255;
    }
  SplatRenderer renderer(ctx(), table, checker);
  const Camera cam = test::camera_at(Vec3(0, 0, 0.5), Vec3::Zero(), Vec3::UnitY(), 30);
  const RgbaImage image = renderer.render(inputs.inputs(), test::setup_for(cam, 96, 96));
  // The middle of the sheet: shaded grey, the same in every pixel to within a few levels.
  std::vector<int> reds;
  for (uint32_t y = 40; y < 56; ++y)
    for (uint32_t x = 40; x < 56; ++x) reds.push_back(image.at(x, y)[0]);
  const auto [lo, hi] = std::minmax_element(reds.begin(), reds.end());
  EXPECT_LE(*hi - *lo, 12) << "aliased: pixels from " << *lo << " to " << *hi;
  const double mean = std::accumulate(reds.begin(), reds.end(), 0.0) / reds.size();
  EXPECT_GT(mean, 40);
  EXPECT_LT(mean, 200);
}

// Every channel in play: texture, cut and torn faces (procedural colours), a mirror fraction
// under an environment, a tool in front, both eyes. The 64-bit path is exact (render_layout.h),
// so the frames are the same bytes.
TEST_F(SplatRaster, PairedAtomicsDrawTheImageOfThe32BitAdds) {
  const PhyxelSet set = lattice_sphere(Vec3::Zero(), 0.02, 0.002, 0.006);
  const NeighbourLists neighbours = find_rest_neighbours(set);
  HostInputs inputs(ctx(), set, neighbours);
  SurfelTable table = build_surfel_table(set, {0.4});
  for (size_t k = 0; k < table.surfels.size(); ++k) {
    if (k % 3 == 0) table.surfels[k].flags |= layout::kSurfelCutFace;
    if (k % 7 == 0) table.surfels[k].flags |= layout::kSurfelCutFace | layout::kSurfelTornFace;
  }
  const Camera cam = test::camera_at(Vec3(0.01, -0.1, 0.02), Vec3::Zero(), Vec3::UnitZ(), 35);
  const FrameSetup setup = test::setup_for(cam, 160, 120, RenderSettings::Mode::Stereo);
  ToolDrawable tool;
  tool.shape.type = ToolShape::Type::Capsule;
  tool.shape.radius = 0.003;
  tool.shape.length = 0.05;
  tool.pose.position = Vec3(-0.01, -0.03, 0.0);
  tool.pose.axis = Vec3(1, 0, 0.3).normalized();
  std::vector<RgbaImage> images;
  for (const bool int64_atomics : {true, false}) {
    RendererOptions options;
    options.int64_atomics = int64_atomics;
    SplatRenderer renderer(ctx(), table, procedural_tissue_texture(64), options);
    EXPECT_EQ(renderer.int64_atomics(), int64_atomics && ctx().int64_atomics());
    renderer.set_environment(procedural_tissue_texture(32), environment_basis(cam), 1.0);
    renderer.set_tools({tool});
    images.push_back(renderer.render(inputs.inputs(), setup));
  }
  if (!ctx().int64_atomics()) std::printf("no shaderBufferInt64Atomics: both 32-bit\n");
  size_t covered = 0;
  for (uint32_t y = 0; y < images[0].height; ++y)
    for (uint32_t x = 0; x < images[0].width; ++x)
      covered += !test::is_background(images[0].at(x, y));
  EXPECT_GT(covered, 5000u);
  EXPECT_TRUE(images[0].pixels == images[1].pixels) << "the two paths' frames differ";
}

// 50 000 coincident discs: at the centre their weights sum to 50 000 x 2^16 in fixed point,
// past 2^31 (a signed int's wrap) though below 2^32 (render_layout.h). The non-negative sums
// are read unsigned, so the pixels are the one disc's (to float rounding), and the next frame
// starts from a clear buffer (a wrapped sum once stayed in it). Normals (1, 1, 1) / sqrt(3):
// their signed sums stay below 2^31. About a second on lavapipe.
TEST_F(SplatRaster, WeightSumsPast2To31DrawTheDiscAndLeaveNoResidue) {
  const Camera cam = test::camera_at(Vec3(0, 0, 0.1), Vec3::Zero(), Vec3::UnitY(), 40);
  const FrameSetup setup = test::setup_for(cam, 25, 25);  // odd: the centre is a pixel's
  const double pixel = 2 * 0.1 * std::tan(20 * M_PI / 180) / 25;
  const Disc d{Vec3::Zero(), Vec3(1, 1, 1), 3 * pixel};
  const RgbaImage one = render_disc(ctx(), d, setup);
  const std::vector<RgbaImage> many = render_discs(ctx(), d, setup, 50000, 2);
  int drawn = 0, worst = 0;
  for (size_t i = 0; i < one.pixels.size(); ++i) {
    drawn += i % 4 == 0 && !test::is_background(&one.pixels[i]);
    worst = std::max(worst, std::abs(int(one.pixels[i]) - int(many[0].pixels[i])));
  }
  EXPECT_GT(drawn, 10);
  EXPECT_LE(worst, 1) << "the 50 000 discs' pixels differ from the one disc's";
  EXPECT_TRUE(many[1].pixels == many[0].pixels) << "the second frame differs from the first";
}

TEST_F(SplatRaster, FramesLargerThanTheDeviceBindsAndEmptyTexturesAreRefused) {
  const PhyxelSet set = lattice_box(Vec3::Zero(), Vec3(0.01, 0.01, 0.01), 0.005);
  const NeighbourLists neighbours = find_rest_neighbours(set);
  HostInputs inputs(ctx(), set, neighbours);
  SplatRenderer renderer(ctx(), build_surfel_table(set), white_texture());
  const Camera cam = test::camera_at(Vec3(0, 0, 0.1), Vec3::Zero(), Vec3::UnitY(), 40);
  // Within the per-side limit, but its accumulation buffer exceeds maxStorageBufferRange
  // (32 bytes per pixel): refused before anything is allocated.
  const uint32_t side = renderer.max_frame_side();
  const uint64_t bytes = uint64_t(side) * side * layout::kAccumChannels * 4;
  ASSERT_GT(bytes, ctx().info().max_storage_buffer_range) << "a device that binds it all";
  const FrameSetup setup = test::setup_for(cam, side, side);
  EXPECT_FALSE(renderer.frame_error(setup).empty());
  try {
    renderer.render(inputs.inputs(), setup);
    ADD_FAILURE() << "a " << side << " x " << side << " frame rendered";
  } catch (const std::invalid_argument& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("maxStorageBufferRange"), std::string::npos) << m;
    EXPECT_NE(m.find(std::to_string(side)), std::string::npos) << m;
  }
  // Too wide for the device, and zero-sized.
  EXPECT_FALSE(renderer.frame_error(test::setup_for(cam, side + 1, 16)).empty());
  FrameSetup empty = test::setup_for(cam, 16, 16);
  empty.height = 0;
  EXPECT_FALSE(renderer.frame_error(empty).empty());
  EXPECT_TRUE(renderer.frame_error(test::setup_for(cam, 64, 48)).empty());
  // An empty texture is refused with a message, not uploaded.
  try {
    SplatRenderer none(ctx(), build_surfel_table(set), RgbaImage());
    ADD_FAILURE() << "an empty texture was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("texture is empty"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace phyxel::render
