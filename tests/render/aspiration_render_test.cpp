// Aspiration drawn (FrameWriter::apply_aspiration, docs/suction.md), on lavapipe with validation:
// an aspirator sucks its way into a block on the CPU reference; every aspiration hides the
// removed phyxels' surfels and draws the crater's wall as torn surface. In the last frame no
// splat of a removed phyxel is drawn, the wall's splats are torn faces, and the crater shows
// tissue, not the background, where the aspirator went in.
#include <gtest/gtest.h>

#include <set>

#include "engine/run/simulation.h"
#include "render/frame_output.h"
#include "tests/cutting/cutting_fixtures.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

class AspirationRender : public gpu::VulkanTest {};

// The suction block (tear stress 1000 Pa), seen from above the aspirator's way in.
Scene suction_scene(uint32_t width, uint32_t height) {
  Scene scene = parse_scene(phyxel::test::suction_block_json(1000, true), "block.json");
  scene.render.width = width;
  scene.render.height = height;
  scene.camera.position = Vec3(0.01, -0.012, 0.035);
  scene.camera.target = Vec3(0.01, 0.01, 0.006);
  scene.camera.up = Vec3::UnitZ();
  scene.camera.fov_y_deg = 40;
  return scene;
}

TEST_F(AspirationRender, RemovedTissueVanishesAndTheCraterWallIsTorn) {
  const Scene scene = suction_scene(640, 480);
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  const std::filesystem::path dir = test::test_out_dir() / "aspiration_render";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, dir}, &ctx());
  std::set<uint32_t> removed, wall;
  RunOptions options;
  options.steps = 250;  // the aspirator still in the crater
  options.on_aspiration = [&](const AspirationEvent& e) {
    writer.apply_aspiration(e);
    removed.insert(e.removed.begin(), e.removed.end());
    wall.insert(e.exposed.begin(), e.exposed.end());
  };
  const RunResult r = run_simulation(scene, set, *solver, options);
  ASSERT_GE(r.aspiration.events, 2);
  for (const uint32_t k : removed) wall.erase(k);  // exposed, then aspirated later
  writer.set_tools({});
  const std::string name =
      writer.write(250, solver->read_state(false).displacement, solver->neighbours());
  writer.flush();  // frames are written on a thread of their own
  std::printf("aspiration frame: %s (%zu removed, %zu wall phyxels)\n", (dir / name).c_str(),
              removed.size(), wall.size());
  size_t drawn_removed = 0, torn_wall = 0;
  const std::vector<layout::SurfelStatic>& table = writer.renderer().surfels();
  for (const layout::SurfelStatic& s : table) {
    if (removed.count(s.index) && s.radius > 0) ++drawn_removed;
    if (wall.count(s.index) && (s.flags & layout::kSurfelTornFace)) ++torn_wall;
  }
  EXPECT_EQ(drawn_removed, 0u) << "aspirated tissue is still drawn";
  EXPECT_GT(torn_wall, wall.size() / 2) << "the crater's wall is not drawn torn";
  // Straight down the aspirator's way in: tissue (the crater's floor or wall), not background.
  const RgbaImage image = load_image(dir / name, "aspiration frame");
  size_t background = 0, pixels = 0;
  for (uint32_t y = 200; y < 280; ++y)
    for (uint32_t x = 280; x < 360; ++x, ++pixels)
      background += test::is_background(image.at(x, y));
  EXPECT_LT(background, pixels / 20) << "the background shows through the crater";
}

// The surfel edits of aspirations reach the GPU with the next frame (SplatRenderer::
// record_surfel_upload): a writer that draws a frame after every aspiration and one that draws
// only at the end draw the same pixels, and no splat of a removed phyxel is drawn.
TEST_F(AspirationRender, EditsUploadedWithTheNextFrameDrawTheSamePixels) {
  const Scene scene = suction_scene(320, 240);
  const PhyxelSet set = sample_scene(scene);
  const std::unique_ptr<Solver> solver = make_cpu_solver(set, Vec3::Zero(), 1);
  FrameWriter each(scene, set, {RenderSettings::Mode::Mono, {}}, &ctx());
  FrameWriter batched(scene, set, {RenderSettings::Mode::Mono, {}}, &ctx());
  std::set<uint32_t> removed;
  int drawn = 0;
  const std::vector<Vec3> rest(set.size(), Vec3::Zero());
  each.render(rest, solver->neighbours());  // both upload the whole table here
  batched.render(rest, solver->neighbours());
  RunOptions options;
  options.steps = 250;
  options.on_aspiration = [&](const AspirationEvent& e) {
    each.apply_aspiration(e);
    batched.apply_aspiration(e);
    removed.insert(e.removed.begin(), e.removed.end());
    each.render(solver->read_state(false).displacement, solver->neighbours());
    ++drawn;
  };
  run_simulation(scene, set, *solver, options);
  ASSERT_GE(drawn, 2);
  const std::vector<Vec3> u = solver->read_state(false).displacement;
  const RgbaImage a = each.render(u, solver->neighbours());
  const RgbaImage b = batched.render(u, solver->neighbours());
  EXPECT_EQ(a.pixels, b.pixels) << "frames differ with the edits batched";
  const std::vector<layout::SurfelStatic>& table = batched.renderer().surfels();
  const std::vector<layout::Splat> splats = batched.renderer().read_splats();
  ASSERT_EQ(splats.size(), table.size());
  size_t drawn_removed = 0;
  for (size_t s = 0; s < table.size(); ++s)
    if (removed.count(table[s].index) && splats[s].centre.w != 0) ++drawn_removed;
  EXPECT_EQ(drawn_removed, 0u) << "a removed phyxel's splat is drawn";
}

// Hides scattered over the whole table (separate blocks of slots, far apart) all reach the GPU with
// the next frame: a splat is drawn (radius > 0) exactly where the host table says so.
TEST_F(AspirationRender, ScatteredHidesReachTheGpuWithTheNextFrame) {
  const Scene scene = suction_scene(160, 120);
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists neighbours = find_rest_neighbours(set);
  FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, {}}, &ctx());
  const std::vector<Vec3> rest(set.size(), Vec3::Zero());
  writer.render(rest, neighbours);
  std::vector<uint32_t> hide;
  const std::vector<layout::SurfelStatic>& table = writer.renderer().surfels();
  for (size_t s = 0; s < table.size(); s += 150) hide.push_back(table[s].index);
  writer.renderer().hide_phyxels(hide);
  writer.render(rest, neighbours);
  const std::vector<layout::Splat> splats = writer.renderer().read_splats();
  ASSERT_EQ(splats.size(), table.size());
  size_t hidden = 0, differ = 0;
  for (size_t s = 0; s < table.size(); ++s) {
    hidden += table[s].radius == 0;
    differ += (splats[s].centre.w == 0) != (table[s].radius == 0);
  }
  EXPECT_GE(hidden, hide.size());
  EXPECT_EQ(differ, 0u) << "the GPU's surfels are not the host table's";
}

}  // namespace
}  // namespace phyxel::render
