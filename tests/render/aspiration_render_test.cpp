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

TEST_F(AspirationRender, RemovedTissueVanishesAndTheCraterWallIsTorn) {
  Scene scene = parse_scene(phyxel::test::suction_block_json(1000, true), "block.json");
  scene.render.width = 640;
  scene.render.height = 480;
  scene.camera.position = Vec3(0.01, -0.012, 0.035);
  scene.camera.target = Vec3(0.01, 0.01, 0.006);
  scene.camera.up = Vec3::UnitZ();
  scene.camera.fov_y_deg = 40;
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

}  // namespace
}  // namespace phyxel::render
