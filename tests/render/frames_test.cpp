// Frames of a run (FrameWriter, write_solver_frame through RunOptions::on_frame) with the CPU
// reference solver and from the GPU solver's own buffers, the render bench entry point, and the
// viewer's one-line refusals.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "bench/render_bench.h"
#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"
#include "render/viewer.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

class RenderFrames : public gpu::VulkanTest {};

// A soft block clamped at its base, sagging under gravity.
Scene block_scene(const std::string& render_json) {
  return parse_scene(R"({"simulation": {"dt": 2e-4, "steps": 25, "gravity": [0, 0, -9.81]},
    "objects": [{"name": "b", "shape": {"type": "box", "min": [-0.02, -0.01, 0],
                 "max": [0.02, 0.01, 0.01]}, "spacing": 0.0025,
                 "material": {"young": 3000, "poisson": 0.3, "density": 1000, "damping": 1},
                 "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [-0.0195, 1, 1]}]}],
    "render": )" + render_json +
                         "}",
                     test::test_out_dir() / "block.json");
}

std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path dir = test::test_out_dir() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST_F(RenderFrames, RunWritesAFrameEveryRenderEveryStepsAndAtTheEnd) {
  const Scene scene = block_scene(R"({"mode": "mono", "width": 64, "height": 48, "every": 10})");
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  const std::filesystem::path dir = fresh_dir("frames_mono");
  FrameWriter writer(scene, set, {scene.render.mode, dir}, &ctx());
  write_solver_frame(writer, *solver, 0, {});
  RunOptions options;
  options.steps = 25;
  options.frame_every = scene.render.every;
  options.on_frame = [&](int64_t step, Solver& s) { write_solver_frame(writer, s, step, {}); };
  run_simulation(scene, set, *solver, options);
  const std::vector<std::string> expected = {"frame_000000.png", "frame_000010.png",
                                             "frame_000020.png", "frame_000025.png"};
  EXPECT_EQ(writer.written(), expected);
  writer.finish();  // the writer thread's files
  RgbaImage first, last;
  for (const std::string& name : expected) {
    const RgbaImage image = load_image(dir / name, name);
    EXPECT_EQ(image.width, 64u);
    EXPECT_EQ(image.height, 48u);
    if (name == expected.front()) first = image;
    last = image;
  }
  // The block is in the picture, and it moved (sagged) between the first and last frame.
  auto covered = [](const uint8_t* p) { return !test::is_background(p); };
  EXPECT_GT(test::centroid(first, covered).z(), 300);
  EXPECT_NE(first.pixels, last.pixels);
}

// --draw-only: the same frames are drawn and read back (the cut faces followed), none written.
TEST_F(RenderFrames, DrawOnlyDrawsEveryFrameAndWritesNone) {
  const Scene scene = block_scene(R"({"mode": "mono", "width": 64, "height": 48, "every": 10})");
  const PhyxelSet set = sample_scene(scene);
  auto solver = make_cpu_solver(set, scene.simulation.gravity, 1);
  const std::filesystem::path dir = fresh_dir("frames_draw_only");
  FrameWriterOptions o{scene.render.mode, dir};
  o.write_files = false;
  FrameWriter writer(scene, set, o, &ctx());
  int drawn = 0;
  RunOptions options;
  options.steps = 25;
  options.frame_every = scene.render.every;
  options.on_frame = [&](int64_t step, Solver& s) {
    EXPECT_EQ(write_solver_frame(writer, s, step, {}),
              "frame_0000" + std::to_string(step) + ".png");
    ++drawn;
  };
  run_simulation(scene, set, *solver, options);
  EXPECT_EQ(drawn, 3);  // steps 10, 20 and the end
  EXPECT_TRUE(writer.written().empty());
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST_F(RenderFrames, StereoLayoutsHaveTheirFrameSizes) {
  const Scene sbs = block_scene(R"({"mode": "stereo", "width": 40, "height": 30})");
  const PhyxelSet set = sample_scene(sbs);
  const std::filesystem::path dir = fresh_dir("frames_stereo");
  const NeighbourLists nbr = find_rest_neighbours(set);
  const std::vector<Vec3> rest(set.size(), Vec3::Zero());
  FrameWriter pair(sbs, set, {RenderSettings::Mode::Stereo, dir}, &ctx());
  const std::string sbs_name = pair.write(3, rest, nbr);
  pair.flush();  // PNG files are written on the writer's thread
  EXPECT_EQ(load_image(dir / sbs_name, "sbs").width, 80u);
  const Scene ana = block_scene(R"({"width": 40, "height": 30, "stereo": {"layout": "anaglyph"}})");
  FrameWriter anaglyph(ana, set, {RenderSettings::Mode::Stereo, dir}, &ctx());
  const std::string anaglyph_name = anaglyph.write(4, rest, nbr);
  anaglyph.flush();
  const RgbaImage a = load_image(dir / anaglyph_name, "anaglyph");
  EXPECT_EQ(a.width, 40u);
  EXPECT_EQ(a.height, 30u);
}

TEST_F(RenderFrames, BadTextureAndOversizedFramesNameTheKey) {
  const std::filesystem::path dir = fresh_dir("frames_errors");
  std::ofstream(dir / "broken.png") << "not a png";
  Scene scene = block_scene(R"({"mode": "mono", "width": 32, "height": 32})");
  const PhyxelSet set = sample_scene(scene);
  scene.render.texture = dir / "broken.png";
  try {
    FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, dir}, &ctx());
    ADD_FAILURE() << "a broken texture was accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("block.json: render.texture: cannot decode"), std::string::npos) << m;
    EXPECT_NE(m.find("broken.png"), std::string::npos) << m;
  }
  scene.render.texture.clear();
  scene.render.width = 1 << 20;  // past any device's maxImageDimension2D
  try {
    FrameWriter writer(scene, set, {RenderSettings::Mode::Stereo, dir}, &ctx());
    ADD_FAILURE() << "an oversized frame was accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("block.json: render.width: a frame of 2097152 x 32 pixels (two eyes"),
              std::string::npos)
        << m;
  }
  // Within the side limit (16384 on lavapipe and NVIDIA), but 32 bytes of accumulation per
  // pixel make 4.6 GB, more than a device binds at once (maxStorageBufferRange <= 4 GiB).
  scene.render.width = scene.render.height = 12000;
  try {
    FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, dir}, &ctx());
    ADD_FAILURE() << "a frame larger than the device binds was accepted";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("block.json: render.width and render.height: a frame of"), std::string::npos)
        << m;
    EXPECT_NE(m.find("maxStorageBufferRange"), std::string::npos) << m;
  }
}

TEST_F(RenderFrames, GpuSolverBuffersRenderLikeTheHostCopyOfTheirState) {
  const Scene scene = block_scene(R"({"mode": "mono", "width": 96, "height": 64})");
  const PhyxelSet set = sample_scene(scene);
  gpu::GpuSolver solver(ctx(), set, scene.simulation.gravity);
  solver.advance(40, plan_time_step(scene, set).dt_used);
  FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, fresh_dir("frames_gpu")}, &ctx());
  // Straight from the solver's four buffers (gpu::SolverBuffers converts to RenderInputs)...
  const RgbaImage from_gpu = writer.render(solver.buffers());
  // ... and from its state read back, through the CPU path's own buffers.
  HostInputs host(ctx(), set, solver.neighbours());
  host.set_displacement(solver.read_state(false).displacement);
  const RgbaImage from_host = writer.render(host.inputs());
  ASSERT_EQ(from_gpu.pixels.size(), from_host.pixels.size());
  int worst = 0;
  for (size_t i = 0; i < from_gpu.pixels.size(); ++i)
    worst = std::max(worst, std::abs(from_gpu.pixels[i] - from_host.pixels[i]));
  EXPECT_LE(worst, 1);
  // The solver's CSR lists are the engine's.
  EXPECT_EQ(solver.neighbours().index, find_rest_neighbours(set).index);
}

// A solver whose neighbour index and pair weights are bound in two parts (as past about 41M
// phyxels; here split mid-row by GpuSolverOptions::pair_part_bytes) deforms the splats from
// both parts: with the pairs across the block's middle severed in both solvers, its frame is
// the one-binding solver's, bit for bit.
TEST_F(RenderFrames, ASolverWithItsPairsInTwoPartsRendersTheOneBindingFrame) {
  const Scene scene = block_scene(R"({"mode": "mono", "width": 96, "height": 64})");
  const PhyxelSet set = sample_scene(scene);
  gpu::GpuSolver whole(ctx(), set, scene.simulation.gravity);
  gpu::GpuSolverOptions options;
  options.pair_part_bytes = (whole.pair_count() / 2 + 7) * 4;
  gpu::GpuSolver split(ctx(), set, scene.simulation.gravity, options);
  std::vector<SeveredPair> cut;
  const NeighbourLists& nbr = whole.neighbours();
  for (uint32_t i = 0; i < set.size(); ++i) {
    for (uint32_t k = nbr.offset[i]; k < nbr.offset[i + 1]; ++k) {
      const uint32_t j = nbr.index[k];
      if (set.rest[i].x() < 0.0 && set.rest[j].x() >= 0.0) cut.push_back({i, j, 0.5f, false});
    }
  }
  ASSERT_GT(cut.size(), 20u);
  const double dt = plan_time_step(scene, set).dt_used;
  for (gpu::GpuSolver* s : {&whole, &split}) {
    s->sever_pairs(cut);
    s->advance(40, dt);
  }
  ASSERT_NE(split.buffers().nbr_index_hi, nullptr);
  ASSERT_EQ(whole.buffers().nbr_index_hi, nullptr);
  FrameWriter writer(scene, set, {RenderSettings::Mode::Mono, fresh_dir("frames_split")}, &ctx());
  const RgbaImage from_whole = writer.render(whole.buffers());
  const RgbaImage from_split = writer.render(split.buffers());
  EXPECT_EQ(from_whole.pixels, from_split.pixels);
  // The cut shows: the frame differs from the uncut solver's.
  gpu::GpuSolver uncut(ctx(), set, scene.simulation.gravity);
  uncut.advance(40, dt);
  EXPECT_NE(writer.render(uncut.buffers()).pixels, from_split.pixels);
}

TEST_F(RenderFrames, BenchEntryPointMeasuresAStereoFrame) {
  bench::RenderBenchOptions options;
  options.surfels = 1500;
  options.eye_width = 64;
  options.height = 48;
  options.frames = 2;
  options.with_solver = true;
  const bench::RenderBenchResult r = bench::bench_render(ctx(), options);
  EXPECT_GT(r.surfels, 1000u);
  EXPECT_LT(r.surfels, 3000u);
  EXPECT_GT(r.phyxels, r.surfels);
  EXPECT_EQ(r.frame_width, 128u);
  EXPECT_EQ(r.frame_height, 48u);
  EXPECT_EQ(r.eyes, 2u);
  EXPECT_EQ(r.frames, 2);
  EXPECT_GT(r.median_frame_s, 0.0);
  EXPECT_GT(r.solver_steps_per_s, 0.0);
  EXPECT_GT(r.solver_steps_per_s_rendering, 0.0);
  EXPECT_GE(r.steps_per_frame, 1);
  EXPECT_GT(r.frames_per_s_rendering, 0.0);
  if (ctx().timestamps()) {
    const std::vector<std::string> expected = {"render clear",      "render deform",
                                               "render visibility", "render accumulate",
                                               "render shade",      "render readback"};
    ASSERT_EQ(r.median_passes.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(r.median_passes[i].name, expected[i]);
      EXPECT_GE(r.median_passes[i].ns, 0.0);
    }
    EXPECT_GT(r.median_gpu_s, 0.0);
    EXPECT_GT(r.solver_frame_gpu_s, 0.0);
  }
}

TEST(RenderViewer, WithoutADisplayOrWindowSupportSaysSoInOneLine) {
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  Scene scene;
  scene.file = "scenes/x.json";
  try {
    run_viewer(scene, {});
    ADD_FAILURE() << "the viewer ran without a display";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find("phyxel run SCENE --render"), std::string::npos) << m;
    if (viewer_available()) {
      EXPECT_NE(m.find("no display"), std::string::npos) << m;
    } else {
      EXPECT_NE(m.find("without the window viewer"), std::string::npos) << m;
    }
  }
}

}  // namespace
}  // namespace phyxel::render
