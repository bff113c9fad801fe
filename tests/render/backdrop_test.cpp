// The backdrop of the surgical field (render/backdrop.h, SplatRenderer::set_backdrop): the
// surface sampling (counts, coverage, holes, culling to the camera's side), the baked looks,
// and frames on lavapipe with validation: the drape's colour where only the drape is, the
// object still drawn in front of it, a hole showing what lies behind, and the solver's state
// bit for bit the same with and without a backdrop.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>

#include "compute/gpu_solver.h"
#include "engine/geometry/shape.h"
#include "engine/run/simulation.h"
#include "render/backdrop.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

using test::RenderedSet;

Shape box(const Vec3& min, const Vec3& max) {
  Shape s;
  s.type = Shape::Type::Box;
  s.min = min;
  s.max = max;
  return s;
}

Shape ellipsoid(const Vec3& centre, const Vec3& radii) {
  Shape s;
  s.type = Shape::Type::Ellipsoid;
  s.center = centre;
  s.radii = radii;
  return s;
}

Shape sphere(const Vec3& centre, double radius) {
  Shape s;
  s.type = Shape::Type::Sphere;
  s.center = centre;
  s.radius = radius;
  return s;
}

BackdropItem item(const Shape& shape, double spacing, BackdropItem::Look look, const Vec3& colour,
                  std::optional<Shape> hole = {}) {
  BackdropItem b;
  b.name = "item";
  b.shape = shape;
  b.spacing = spacing;
  b.look = look;
  b.colour = colour;
  b.hole = hole;
  return b;
}

TEST(Backdrop, BoxSamplesAboutAreaOverSpacingSquared) {
  const double s = 0.005;
  const std::vector<BackdropSample> samples =
      sample_backdrop_surface(box(Vec3(-0.1, -0.05, 0), Vec3(0.1, 0.05, 0.01)), s);
  const double area = 2 * (0.2 * 0.1 + 0.2 * 0.01 + 0.1 * 0.01);
  EXPECT_NEAR(double(samples.size()), area / (s * s), 0.05 * area / (s * s));
  for (const BackdropSample& b : samples) {
    // On a face, the normal along that face's axis, outward.
    const Vec3 c(0, 0, 0.005);
    EXPECT_NEAR(b.normal.norm(), 1, 1e-12);
    EXPECT_GT(b.normal.dot(b.position - c), 0);
    EXPECT_LT(b.radius, 1.2 * s);
  }
}

TEST(Backdrop, EllipsoidSamplesCoverItsSurface) {
  const Vec3 centre(0.01, -0.02, 0.03), radii(0.05, 0.08, 0.03);
  const double s = 0.004;
  const std::vector<BackdropSample> samples = sample_backdrop_surface(ellipsoid(centre, radii), s);
  // Thomsen's area (within 1 %) over s^2.
  const double p = 1.6075, a = std::pow(radii.x(), p), b = std::pow(radii.y(), p),
               c = std::pow(radii.z(), p);
  const double area = 4 * M_PI * std::pow((a * b + a * c + b * c) / 3, 1 / p);
  EXPECT_NEAR(double(samples.size()), area / (s * s), 0.03 * area / (s * s));
  for (const BackdropSample& x : samples) {
    EXPECT_NEAR((x.position - centre).cwiseQuotient(radii).norm(), 1, 1e-9);
    EXPECT_GT(x.normal.dot(x.position - centre), 0);
  }
  // Every point of the surface lies within some sample's disc (its radius in 3-D).
  std::mt19937 rng(3);
  std::normal_distribution<double> g;
  int uncovered = 0;
  for (int k = 0; k < 400; ++k) {
    const Vec3 q = centre + radii.cwiseProduct(Vec3(g(rng), g(rng), g(rng)).normalized());
    bool covered = false;
    for (const BackdropSample& x : samples) covered |= (q - x.position).norm() <= x.radius;
    uncovered += !covered;
  }
  EXPECT_EQ(uncovered, 0);
}

TEST(Backdrop, NothingInsideTheHoleAndOnlyTheCameraSide) {
  const Vec3 eye(0.02, -0.1, 0.3);
  const Shape hole = sphere(Vec3(0, 0, 0), 0.04);
  const std::vector<BackdropItem> items = {item(box(Vec3(-0.15, -0.15, -0.01), Vec3(0.15, 0.15, 0)),
                                                0.005, BackdropItem::Look::Drape,
                                                Vec3(0.2, 0.5, 0.55), hole)};
  const std::vector<layout::Splat> splats = bake_backdrop(items, eye);
  // The top face only (the others face away or are edge on... the sides facing the eye stay).
  const double top = 0.3 * 0.3 - M_PI * 0.04 * 0.04;
  EXPECT_GT(double(splats.size()), 0.95 * top / (0.005 * 0.005));
  EXPECT_LT(double(splats.size()), 1.15 * top / (0.005 * 0.005));
  for (const layout::Splat& s : splats) {
    const Vec3 c(s.centre.x, s.centre.y, s.centre.z);
    EXPECT_FALSE(shape_contains(hole, c)) << c.transpose();
    const Vec3 n(s.normal.x, s.normal.y, s.normal.z);
    EXPECT_GT(n.dot(eye - c), 0) << "a splat faces away from the camera";
    EXPECT_EQ(uint32_t(s.normal.w), layout::kSplatBaked | layout::kSplatUsable);
    EXPECT_GT(s.centre.w, 0);
  }
  // A closed ellipsoid keeps about the half its camera sees.
  const std::vector<BackdropItem> skull = {item(ellipsoid(Vec3(0, 0, -0.05), Vec3(0.08, 0.1, 0.09)),
                                                0.004, BackdropItem::Look::Bone,
                                                Vec3(0.9, 0.85, 0.7))};
  const size_t all = sample_backdrop_surface(skull[0].shape, 0.004).size();
  const size_t seen = bake_backdrop(skull, eye).size();
  EXPECT_GT(seen, all / 3);
  EXPECT_LT(seen, 2 * all / 3);
}

TEST(Backdrop, WithinKeepsOnlyThePartInsideIt) {
  BackdropItem skull = item(ellipsoid(Vec3(0, 0, -0.05), Vec3(0.08, 0.1, 0.09)), 0.003,
                            BackdropItem::Look::Bone, Vec3(0.9, 0.85, 0.7));
  const Vec3 eye(0, 0, 0.5);
  const size_t all = bake_backdrop({skull}, eye).size();
  skull.within = box(Vec3(-0.03, -0.03, -1), Vec3(0.03, 0.03, 1));
  const std::vector<layout::Splat> kept = bake_backdrop({skull}, eye);
  EXPECT_GT(kept.size(), 100u);
  EXPECT_LT(kept.size(), all / 4);
  for (const layout::Splat& s : kept) {
    EXPECT_TRUE(shape_contains(*skull.within, Vec3(s.centre.x, s.centre.y, s.centre.z)));
  }
}

TEST(Backdrop, LooksAreBakedNearTheirColour) {
  const Shape hole = sphere(Vec3::Zero(), 0.03);
  const BackdropItem drape = item(box(Vec3(-0.1, -0.1, -0.01), Vec3(0.1, 0.1, 0)), 0.004,
                                  BackdropItem::Look::Drape, Vec3(0.2, 0.5, 0.55));
  const BackdropItem bone = item(ellipsoid(Vec3(0, 0, -0.05), Vec3(0.08, 0.1, 0.09)), 0.002,
                                 BackdropItem::Look::Bone, Vec3(0.88, 0.83, 0.7), hole);
  double tilt = 0;
  int n = 0;
  for (const BackdropSample& s : sample_backdrop_surface(drape.shape, drape.spacing)) {
    const BakedLook a = bake_look(drape, s), b = bake_look(drape, s);
    EXPECT_EQ(a.colour, b.colour);  // deterministic
    EXPECT_GT(a.colour.y(), a.colour.x() + 0.1) << "blue-green";
    EXPECT_LT((a.colour - drape.colour).norm(), 0.25);
    EXPECT_GT(a.normal.dot(s.normal), 0.7);
    tilt += 1 - a.normal.dot(s.normal);
    ++n;
  }
  EXPECT_GT(tilt / n, 1e-3) << "folds tilt the normals";
  // The bone's rim at the hole is darker and redder than the bone away from it.
  BackdropSample rim{Vec3(0, 0.0302, 0), Vec3::UnitZ(), 0.002};
  BackdropSample away{Vec3(0, 0.07, 0.01), Vec3::UnitZ(), 0.002};
  const Vec3 at_rim = bake_look(bone, rim).colour, far = bake_look(bone, away).colour;
  EXPECT_LT(at_rim.z(), far.z() - 0.1);
  EXPECT_GT(at_rim.x() - at_rim.z(), far.x() - far.z());
}

class BackdropRender : public gpu::VulkanTest {};

// A tissue ball above a drape with a hole beside the ball, seen from above.
struct DrapeScene {
  Camera camera = test::camera_at(Vec3(0, -0.03, 0.15), Vec3(0, 0, 0), Vec3::UnitZ(), 40);
  Shape hole = sphere(Vec3(0.035, 0, -0.02), 0.012);
  std::vector<BackdropItem> items = {item(box(Vec3(-0.2, -0.2, -0.025), Vec3(0.2, 0.2, -0.02)),
                                          0.006, BackdropItem::Look::Drape, Vec3(0.2, 0.5, 0.55),
                                          hole)};
};

TEST_F(BackdropRender, DrapeAroundTheObjectHoleShowsThrough) {
  const DrapeScene scene;
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006),
                procedural_tissue_texture(64));
  const uint32_t w = 160, h = 120;
  const FrameSetup setup = test::setup_for(scene.camera, w, h);
  const RgbaImage plain = s.render(setup);
  s.renderer->set_backdrop(bake_backdrop(scene.items, scene.camera.position));
  EXPECT_GT(s.renderer->backdrop_count(), 1000u);
  const RgbaImage draped = s.render(setup);
  write_png(test::test_out_dir() / "backdrop_drape.png", draped);
  const EyeView& eye = setup.eyes[0];
  // The corners: drape only (blue-green), the plain background without the backdrop.
  for (const auto& [x, y] : {std::pair{4u, 4u}, {w - 5, 4u}, {4u, h - 5}, {w - 5, h - 5}}) {
    const uint8_t* p = draped.at(x, y);
    EXPECT_GT(p[1], p[0] + 30) << x << "," << y;
    EXPECT_GT(p[2], p[0] + 30) << x << "," << y;
    EXPECT_TRUE(test::is_background(plain.at(x, y))) << x << "," << y;
  }
  // The ball's middle: the tissue as before, not the drape behind it.
  const Eigen::Vector3d c = project_to_pixel(eye, Vec3(0, 0, 0.012), w, h);
  for (int dy = -3; dy <= 3; ++dy)
    for (int dx = -3; dx <= 3; ++dx) {
      const uint8_t* a = draped.at(uint32_t(c.x()) + dx, uint32_t(c.y()) + dy);
      const uint8_t* b = plain.at(uint32_t(c.x()) + dx, uint32_t(c.y()) + dy);
      for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(a[ch], b[ch]);
    }
  // Through the hole's middle: nothing (the background), the drape around it.
  const Eigen::Vector3d in = project_to_pixel(eye, Vec3(0.035, 0, -0.02), w, h);
  EXPECT_TRUE(test::is_background(draped.at(uint32_t(in.x()), uint32_t(in.y()))));
  const Eigen::Vector3d out = project_to_pixel(eye, Vec3(0.065, 0, -0.02), w, h);
  const uint8_t* p = draped.at(uint32_t(out.x()), uint32_t(out.y()));
  EXPECT_GT(p[1], p[0] + 30);
}

bool steel(const uint8_t* p) {
  const int hi = std::max({p[0], p[1], p[2]}), lo = std::min({p[0], p[1], p[2]});
  return hi - lo <= 24 && p[2] >= p[0];
}

// Tools against the backdrop's layer: one above the drape shows, one under it does not.
TEST_F(BackdropRender, ToolsAboveTheDrapeShowThoseUnderItDoNot) {
  const DrapeScene scene;
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006),
                procedural_tissue_texture(64));
  const uint32_t w = 160, h = 120;
  const FrameSetup setup = test::setup_for(scene.camera, w, h);
  s.renderer->set_backdrop(bake_backdrop(scene.items, scene.camera.position));
  const Vec3 axis = Vec3(0, 1, 0);
  s.renderer->set_tools(
      {{{ToolShape::Type::Capsule, 0.003, 0.03}, {Vec3(-0.04, -0.015, -0.01), axis}},
       {{ToolShape::Type::Capsule, 0.003, 0.03}, {Vec3(0.04, -0.035, -0.04), axis}}});
  const RgbaImage image = s.render(setup);
  write_png(test::test_out_dir() / "backdrop_tools.png", image);
  const EyeView& eye = setup.eyes[0];
  const Eigen::Vector3d above = project_to_pixel(eye, Vec3(-0.04, 0, -0.007), w, h);
  EXPECT_TRUE(steel(image.at(uint32_t(above.x()), uint32_t(above.y()))));
  const Eigen::Vector3d under = project_to_pixel(eye, Vec3(0.04, -0.02, -0.037), w, h);
  const uint8_t* p = image.at(uint32_t(under.x()), uint32_t(under.y()));
  EXPECT_GT(p[1], p[0] + 30) << "the drape, not the tool under it";
}

// The layer is drawn once per view: a renderer that drew another view first gives the same
// frame as a fresh one; both eyes of a stereo frame have it.
TEST_F(BackdropRender, LayerFollowsTheViewAndBothEyes) {
  const DrapeScene scene;
  const Camera other = test::camera_at(Vec3(0.05, -0.06, 0.12), Vec3(0, 0, 0), Vec3::UnitZ(), 40);
  const uint32_t w = 96, h = 72;
  auto make = [&] {
    auto r = std::make_unique<RenderedSet>(ctx(), lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006),
                                           procedural_tissue_texture(64));
    r->renderer->set_backdrop(bake_backdrop(scene.items, scene.camera.position));
    return r;
  };
  auto a = make(), b = make();
  a->render(test::setup_for(scene.camera, w, h));
  const RgbaImage moved = a->render(test::setup_for(other, w, h));
  const RgbaImage fresh = b->render(test::setup_for(other, w, h));
  EXPECT_EQ(moved.pixels, fresh.pixels);
  const RgbaImage stereo =
      a->render(test::setup_for(scene.camera, w, h, RenderSettings::Mode::Stereo));
  ASSERT_EQ(stereo.width, 2 * w);
  for (const uint32_t x : {3u, w + 3u, w - 4, 2 * w - 4}) {
    const uint8_t* p = stereo.at(x, 3);
    EXPECT_GT(p[1], p[0] + 30) << "x " << x;
  }
}

TEST_F(BackdropRender, ClearedByAnEmptyListAndRejectsUnbakedSplats) {
  RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006),
                procedural_tissue_texture(64));
  const DrapeScene scene;
  const FrameSetup setup = test::setup_for(scene.camera, 64, 48);
  const RgbaImage plain = s.render(setup);
  s.renderer->set_backdrop(bake_backdrop(scene.items, scene.camera.position));
  s.renderer->set_backdrop({});
  EXPECT_EQ(s.render(setup).pixels, plain.pixels);
  layout::Splat bad{};
  bad.centre = {0, 0, 0, 0.01f};
  EXPECT_THROW(s.renderer->set_backdrop({bad}), std::invalid_argument);
}

// The backdrop is drawn, never simulated: a run's state is bit for bit the same with and
// without one, on the CPU solver (frames through the host copy) and the GPU solver (frames from
// its own buffers, on its queue).
TEST_F(BackdropRender, SolverStateIsBitIdenticalWithAndWithout) {
  const std::string text = R"({"simulation": {"dt": 2e-4, "steps": 30, "gravity": [0, 0, -9.81]},
    "objects": [{"name": "b", "shape": {"type": "box", "min": [-0.02, -0.01, 0],
                 "max": [0.02, 0.01, 0.01]}, "spacing": 0.0025,
                 "material": {"young": 3000, "poisson": 0.3, "density": 1000},
                 "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [-0.015, 1, 1]}]}],
    "camera": {"position": [0, -0.08, 0.1], "target": [0, 0, 0]},
    "render": {"mode": "mono", "width": 64, "height": 48)";
  const std::string backdrop = R"(, "backdrop": [{"name": "drape", "look": "drape",
    "spacing": 0.005, "shape": {"type": "box", "min": [-0.1, -0.1, -0.01], "max": [0.1, 0.1, 0]},
    "hole": {"type": "sphere", "center": [0, 0, 0], "radius": 0.03}}]}})";
  const std::filesystem::path dir = test::test_out_dir() / "backdrop_run";
  std::filesystem::create_directories(dir);
  std::vector<std::vector<Vec3>> cpu, gpu_state;
  for (const bool with : {false, true}) {
    const Scene scene =
        parse_scene(text + (with ? backdrop : std::string("}}")), dir / "block.json");
    ASSERT_EQ(scene.render.backdrop.size(), with ? 1u : 0u);
    const PhyxelSet set = sample_scene(scene);
    const double dt = plan_time_step(scene, set).dt_used;
    FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, dir}, &ctx());
    EXPECT_EQ(writer.renderer().backdrop_count() > 0, with);
    auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
    gpu::GpuSolver gpu(ctx(), set, scene.simulation.gravity);
    for (int k = 0; k < 3; ++k) {
      solver->advance(10, dt);
      writer.write(k, solver->read_state(false).displacement, solver->neighbours());
      gpu.advance(10, dt);
      writer.render(gpu.buffers());
    }
    cpu.push_back(solver->read_state(false).displacement);
    gpu_state.push_back(gpu.read_state(false).displacement);
  }
  ASSERT_EQ(cpu[0].size(), cpu[1].size());
  double moved = 0;
  for (size_t i = 0; i < cpu[0].size(); ++i) {
    ASSERT_EQ(cpu[0][i], cpu[1][i]) << "phyxel " << i;
    ASSERT_EQ(gpu_state[0][i], gpu_state[1][i]) << "phyxel " << i;
    moved = std::max(moved, cpu[0][i].norm());
  }
  EXPECT_GT(moved, 0) << "the block sagged";
}

// phyxel bench --render --scene: a row without and one with the scene's backdrop, each with
// its frame time still and while the view turns every frame (the viewer's drag).
TEST(BackdropBench, SceneBenchTimesFramesStillAndOrbitingWithAndWithoutTheBackdrop) {
  const std::filesystem::path json = test::test_out_dir() / "bench_render_scene.json";
  const std::string cmd = std::string(PHYXEL_BINARY_DIR) +
                          "/app/phyxel bench --render --scene " PHYXEL_SOURCE_DIR
                          "/scenes/brain_tumour.json --width 64 --height 48 --frames 2 --json " +
                          json.string() + " > " + json.string() + ".out 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "see " << json << ".out";
  std::ifstream in(json);
  const nlohmann::json rows = nlohmann::json::parse(in);
  ASSERT_EQ(rows.size(), 2u) << rows.dump();
  EXPECT_FALSE(rows[0]["backdrop"].get<bool>());
  EXPECT_TRUE(rows[1]["backdrop"].get<bool>());
  EXPECT_EQ(rows[0]["backdrop_splats"].get<int>(), 0);
  EXPECT_GT(rows[1]["backdrop_splats"].get<int>(), 1000);
  for (const nlohmann::json& row : rows) {
    EXPECT_GT(row["median_frame_ms"].get<double>(), 0.0) << row.dump();
    EXPECT_GT(row["median_orbit_frame_ms"].get<double>(), 0.0) << row.dump();
  }
}

}  // namespace
}  // namespace phyxel::render
