// Tools in the splat renderer (render/tool_raycast.h, the tool pass): the CPU twin of the ray
// cast against sphere tracing of tool_distance, and frames on lavapipe with validation: a
// steel capsule in front of and inside a splatted sphere (mono), in both eyes with the
// parallax of the focal distance (side by side and anaglyph), and no change without tools.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "engine/run/simulation.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"
#include "render/tool_raycast.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

using test::RenderedSet;

// Sphere tracing of the signed distance: steps of the distance itself never pass the surface,
// so the first t where it drops below `tol` is the first hit. Returns -1 on a miss (the ray
// left the region or started inside).
double march(const ToolShape& shape, const ToolPose& pose, const Vec3& o, const Vec3& d,
             double t_max, double tol) {
  if (tool_distance(shape, pose, o).distance <= 0) return -1;
  double t = 0;
  for (int i = 0; i < 100000 && t < t_max; ++i) {
    const double dist = tool_distance(shape, pose, o + t * d).distance;
    if (dist < tol) return t;
    t += dist;
  }
  return -1;
}

// The smallest distance from the tool to the ray's points in [0, t_max] (sampled finely):
// rays that pass within a hair of the surface are left out of the comparison.
double closest_pass(const ToolShape& shape, const ToolPose& pose, const Vec3& o, const Vec3& d,
                    double t_max) {
  double best = 1e300;
  for (int i = 0; i <= 4000; ++i)
    best = std::min(best, tool_distance(shape, pose, o + (t_max * i / 4000.0) * d).distance);
  return best;
}

TEST(ToolRaycast, MatchesSphereTracingOfToolDistance) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  auto unit = [&] {
    Vec3 v;
    do v = Vec3(u(rng), u(rng), u(rng));
    while (v.norm() < 0.1 || v.norm() > 1);
    return Vec3(v.normalized());
  };
  int hits = 0, misses = 0, compared = 0;
  for (int trial = 0; trial < 400; ++trial) {
    ToolShape shape;
    shape.type = trial % 3 == 0 ? ToolShape::Type::Sphere : ToolShape::Type::Capsule;
    shape.radius = 0.002 + 0.004 * (u(rng) + 1);
    shape.length = shape.type == ToolShape::Type::Capsule ? 0.05 * (u(rng) + 1.2) : 0.0;
    ToolPose pose{Vec3(0.02 * u(rng), 0.02 * u(rng), 0.02 * u(rng)), unit()};
    // Rays from a shell around the tool, aimed near it (many hit, many miss, some graze).
    const Vec3 o = 0.15 * unit();
    const Vec3 aim = pose.position + (0.5 + 0.5 * u(rng)) * shape.length * pose.axis +
                     0.012 * Vec3(u(rng), u(rng), u(rng));
    const Vec3 d = (aim - o).normalized();
    const double t_max = 0.4;
    if (std::abs(closest_pass(shape, pose, o, d, t_max)) < 2e-5) continue;  // grazing
    ++compared;
    const ToolRayHit h = intersect_tool(shape, pose, o, d);
    const double t = march(shape, pose, o, d, t_max, 1e-12);
    ASSERT_EQ(h.hit, t >= 0) << "trial " << trial;
    if (!h.hit) {
      ++misses;
      continue;
    }
    ++hits;
    EXPECT_NEAR(h.t, t, 1e-9) << "trial " << trial;
    const ToolDistance at = tool_distance(shape, pose, o + h.t * d);
    EXPECT_NEAR(at.distance, 0, 1e-12);
    EXPECT_LT((h.normal - at.normal).norm(), 1e-6) << "trial " << trial;
    EXPECT_LT(h.normal.dot(d), 0) << "an entry faces the ray";
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(misses, 50);
  EXPECT_GT(compared, 300);

  // A ray along the capsule's axis meets the ball at the tip; one from inside meets nothing.
  ToolShape capsule{ToolShape::Type::Capsule, 0.003, 0.04};
  const ToolPose pose{Vec3(0, 0, 0), Vec3::UnitZ()};
  const ToolRayHit along = intersect_tool(capsule, pose, Vec3(0, 0, -0.1), Vec3::UnitZ());
  ASSERT_TRUE(along.hit);
  EXPECT_NEAR(along.t, 0.1 - 0.003, 1e-12);
  EXPECT_FALSE(intersect_tool(capsule, pose, Vec3(0, 0, 0.02), Vec3::UnitX()).hit);
}

class ToolRender : public gpu::VulkanTest {};

bool steel(const uint8_t* p) {
  const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
  return !test::is_background(p) && hi - lo <= 24 && p[2] >= p[0];
}
bool tissue(const uint8_t* p) {
  return !test::is_background(p) && p[0] > p[1] + 12 && p[0] > p[2] + 12;
}

// The nearest entry of a ray from the origin into the ball (c, r), or -1.
double ball_t(const Vec3& dir, const Vec3& c, double r) {
  const double b = dir.dot(c);
  const double h = r * r - (c - b * dir).squaredNorm();
  return h < 0 ? -1 : b - std::sqrt(h);
}

// The tissue sphere and a steel probe whose tip is buried in it (hidden), whose shaft leaves
// its front (in front of the tissue) and reaches past its silhouette (against the background).
struct ProbeScene {
  static constexpr double kRadius = 0.012, kSpacing = 0.002;
  Camera camera = test::camera_at(Vec3(0.01, -0.07, 0.015), Vec3(0.006, 0, 0), Vec3::UnitZ(), 35);
  std::vector<ToolDrawable> tools = {
      {{ToolShape::Type::Capsule, 0.0022, 0.045},
       {Vec3(-0.003, -0.004, -0.002), Vec3(0.75, -0.45, 0.5).normalized()}}};
};

TEST_F(ToolRender, SteelWhereTheToolIsNearestTissueWhereItIsInFront) {
  const ProbeScene scene;
  RenderedSet s(ctx(),
                lattice_sphere(Vec3::Zero(), ProbeScene::kRadius, ProbeScene::kSpacing,
                               3 * ProbeScene::kSpacing),
                procedural_tissue_texture(128));
  const uint32_t size = 128;
  const FrameSetup setup = test::setup_for(scene.camera, size, size);
  s.renderer->set_tools(scene.tools);
  const RgbaImage image = s.render(setup);
  write_png(test::test_out_dir() / "tool_probe_mono.png", image);

  // The tissue's surface lies between the balls of radius R - 1.5 s (every ray into it meets
  // tissue first) and R + 0.5 s (no splat reaches beyond).
  const EyeView& eye = setup.eyes[0];
  const Vec3 centre = eye.view.topRightCorner<3, 1>();  // the sphere's centre in eye space
  const double inner = ProbeScene::kRadius - 1.5 * ProbeScene::kSpacing;
  const double outer = ProbeScene::kRadius + 0.5 * ProbeScene::kSpacing;
  auto tool_hit = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= int(size) || y >= int(size)) return false;
    return tool_at_pixel(eye, size, size, scene.tools, x, y).tool >= 0;
  };
  int tool_px = 0, hidden_px = 0, tissue_px = 0, background_px = 0, bright = 0, dark = 0;
  std::string wrong;
  for (uint32_t y = 0; y < size; ++y)
    for (uint32_t x = 0; x < size; ++x) {
      const ToolPixel tp = tool_at_pixel(eye, size, size, scene.tools, x, y);
      // The tool's silhouette may fall either way between float and double.
      const bool edge =
          tool_hit(x - 1, y) != tool_hit(x + 1, y) || tool_hit(x, y - 1) != tool_hit(x, y + 1);
      if (edge) continue;
      const Eigen::Vector3d dir =
          Vec3(eye.frustum.left + (x + 0.5) / size * (eye.frustum.right - eye.frustum.left),
               eye.frustum.top + (y + 0.5) / size * (eye.frustum.bottom - eye.frustum.top),
               -eye.frustum.near)
              .normalized();
      const double t_tool =
          tp.tool >= 0 ? eye.frustum.near + tp.depth * (eye.frustum.far - eye.frustum.near) : 1e9;
      const double t_tool_ray = t_tool / -dir.z();
      const double t_out = ball_t(dir, centre, outer), t_in = ball_t(dir, centre, inner);
      const uint8_t* p = image.at(x, y);
      const char* expect = nullptr;
      bool ok = true;
      if (tp.tool >= 0 && (t_out < 0 || t_tool_ray < t_out)) {
        expect = "steel";
        ok = steel(p);
        ++tool_px;
        bright += p[0] >= 180;
        dark += p[0] < 100;
      } else if (t_in > 0 && t_in < t_tool_ray) {
        expect = "tissue";
        ok = tissue(p);
        ++tissue_px;
        hidden_px += tp.tool >= 0;
      } else if (tp.tool < 0 && t_out < 0) {
        expect = "background";
        ok = test::is_background(p);
        ++background_px;
      }
      if (!ok && wrong.size() < 400)
        wrong += " (" + std::to_string(x) + "," + std::to_string(y) + ": " + expect + ", got " +
                 std::to_string(p[0]) + " " + std::to_string(p[1]) + " " + std::to_string(p[2]) +
                 ")";
    }
  EXPECT_TRUE(wrong.empty()) << "pixels of the wrong kind:" << wrong;
  EXPECT_GT(tool_px, 300);
  EXPECT_GT(hidden_px, 40) << "the buried tip is hidden by the tissue in front of it";
  EXPECT_GT(tissue_px, 1500);
  EXPECT_GT(background_px, 3000);
  // Metal: a specular highlight and dark reflections along the shaft, not a flat grey.
  EXPECT_GT(bright, 5);
  EXPECT_GT(dark, 20);
}

TEST_F(ToolRender, StereoBothEyesWithTheParallaxOfTheFocalDistance) {
  RenderedSet s(ctx(), lattice_sphere(Vec3(0.035, 0.05, 0.015), 0.01, 0.002, 0.006),
                procedural_tissue_texture(64));
  const Camera cam = test::camera_at(Vec3(0, -0.3, 0), Vec3::Zero(), Vec3::UnitZ(), 30);
  StereoSettings st;
  st.ipd = 0.03;
  st.focal_distance = 0.3;
  const uint32_t w = 96, h = 72;
  const FrameSetup pair = test::setup_for(cam, w, h, RenderSettings::Mode::Stereo, st);
  StereoSettings ana = st;
  ana.layout = StereoSettings::Layout::Anaglyph;
  const FrameSetup anaglyph = test::setup_for(cam, w, h, RenderSettings::Mode::Stereo, ana);
  // A probe nearer than the focal distance (crossed parallax), then one farther (uncrossed).
  for (const double y : {-0.12, 0.1}) {
    const std::vector<ToolDrawable> tools = {
        {{ToolShape::Type::Capsule, 0.006, 0.06},
         {Vec3(-0.03, y, -0.015), Vec3(1, 0, 1).normalized()}}};
    s.renderer->set_tools(tools);
    const RgbaImage image = s.render(pair);
    const std::string tag = y < 0 ? "near" : "far";
    write_png(test::test_out_dir() / ("tool_stereo_" + tag + ".png"), image);
    ASSERT_EQ(image.width, 2 * w);
    double shift[2] = {0, 0};
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector3d gpu = test::centroid(image, steel, e * w, w);
      double sx = 0, sy = 0, n = 0;
      for (uint32_t py = 0; py < h; ++py)
        for (uint32_t px = 0; px < w; ++px)
          if (tool_at_pixel(pair.eyes[e], w, h, tools, px, py).tool >= 0) {
            sx += px + 0.5;
            sy += py + 0.5;
            n += 1;
          }
      ASSERT_GT(n, 60) << tag << " eye " << e;
      EXPECT_NEAR(gpu.z(), n, 0.03 * n) << tag << " eye " << e << ": steel pixels";
      EXPECT_NEAR(gpu.x(), sx / n, 0.3) << tag << " eye " << e;
      EXPECT_NEAR(gpu.y(), sy / n, 0.3) << tag << " eye " << e;
      shift[e] = gpu.x();
    }
    if (y < 0) {
      EXPECT_LT(shift[1] - shift[0], -2.0) << "nearer than the focal distance: crossed";
    } else {
      EXPECT_GT(shift[1] - shift[0], 1.0) << "farther than the focal distance: uncrossed";
    }
    // The anaglyph of the same eyes: red from the left, green and blue from the right.
    const RgbaImage red_cyan = s.render(anaglyph);
    write_png(test::test_out_dir() / ("tool_anaglyph_" + tag + ".png"), red_cyan);
    for (uint32_t py = 0; py < h; ++py)
      for (uint32_t px = 0; px < w; ++px) {
        ASSERT_EQ(red_cyan.at(px, py)[0], image.at(px, py)[0]);
        ASSERT_EQ(red_cyan.at(px, py)[1], image.at(px + w, py)[1]);
        ASSERT_EQ(red_cyan.at(px, py)[2], image.at(px + w, py)[2]);
      }
  }
}

TEST_F(ToolRender, WithoutToolsTheFrameIsUnchanged) {
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006),
                procedural_tissue_texture(64));
  const Camera cam = test::camera_at(Vec3(0.02, -0.08, 0.03), Vec3::Zero(), Vec3::UnitZ(), 35);
  const FrameSetup setup = test::setup_for(cam, 64, 64);
  const RgbaImage before = s.render(setup);
  // A tool behind the camera: the tool pass runs and finds nothing.
  s.renderer->set_tools(
      {{{ToolShape::Type::Sphere, 0.01, 0}, {Vec3(0.04, -0.2, 0.1), Vec3::UnitZ()}}});
  const RgbaImage unseen = s.render(setup);
  s.renderer->set_tools(
      {{{ToolShape::Type::Sphere, 0.004, 0}, {Vec3(0, -0.02, 0), Vec3::UnitZ()}}});
  const RgbaImage seen = s.render(setup);
  s.renderer->set_tools({});
  const RgbaImage after = s.render(setup);
  EXPECT_EQ(before.pixels, unseen.pixels);
  EXPECT_EQ(before.pixels, after.pixels);
  EXPECT_NE(before.pixels, seen.pixels) << "a tool in view changes the frame";
  EXPECT_THROW(s.renderer->set_tools({{{ToolShape::Type::Sphere, 0, 0}, {}}}),
               std::invalid_argument);
  EXPECT_THROW(
      s.renderer->set_tools({{{ToolShape::Type::Sphere, 0.01, 0}, {Vec3::Zero(), Vec3(0, 0, 2)}}}),
      std::invalid_argument);
}

// A run's frames (FrameWriter, write_solver_frame) draw the tools at the poses they are given:
// a probe sliding along its path above a block, at the start and at the end of the path.
TEST_F(ToolRender, RunFramesDrawTheToolsAtThePosesTheyAreGiven) {
  Scene scene = parse_scene(
      R"({"simulation": {"dt": 2e-4, "steps": 25},
    "objects": [{"name": "b", "shape": {"type": "box", "min": [-0.02, -0.01, 0],
                 "max": [0.02, 0.01, 0.01]}, "spacing": 0.0025,
                 "material": {"young": 3000, "poisson": 0.3, "density": 1000}}],
    "render": {"mode": "mono", "width": 96, "height": 64}})",
      test::test_out_dir() / "probe_block.json");
  ToolDesc probe;
  probe.name = "probe";
  probe.shape = {ToolShape::Type::Capsule, 0.0025, 0.02};
  const Vec3 axis = Vec3(0, -0.3, 1).normalized();
  probe.path = {{0.0, Vec3(-0.014, -0.004, 0.013), axis},
                {0.005, Vec3(0.014, -0.004, 0.013), axis}};
  scene.tools = {probe};
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  const std::filesystem::path dir = test::test_out_dir() / "tool_frames";
  std::filesystem::create_directories(dir);
  FrameWriter writer(scene, set, {scene.render.mode, dir}, &ctx());
  const FrameSetup& setup = writer.setup();
  double previous_x = -1;
  for (const int64_t step : {0, 25}) {
    const std::vector<ToolDrawable> tools =
        tool_drawables(scene.tools, double(step) * scene.simulation.dt);
    const std::string name = write_solver_frame(writer, *solver, step, tools);
    writer.flush();  // frames are written on a thread of their own
    const RgbaImage image = load_image(dir / name, name);
    double sx = 0, n = 0;
    for (uint32_t y = 0; y < setup.height; ++y)
      for (uint32_t x = 0; x < setup.eye_width; ++x)
        if (tool_at_pixel(setup.eyes[0], setup.eye_width, setup.height, tools, x, y).tool >= 0) {
          sx += x + 0.5;
          n += 1;
        }
    const Eigen::Vector3d steel_at = test::centroid(image, steel);
    ASSERT_GT(n, 40) << "step " << step;
    EXPECT_NEAR(steel_at.z(), n, 0.1 * n) << "step " << step << ": the probe is in front";
    EXPECT_NEAR(steel_at.x(), sx / n, 0.75) << "step " << step;
    if (previous_x >= 0) {
      EXPECT_GT(steel_at.x() - previous_x, 10) << "it moved along its path";
    }
    previous_x = steel_at.x();
  }
}

}  // namespace
}  // namespace phyxel::render
