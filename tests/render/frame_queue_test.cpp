// FrameQueue (render/frame_queue.h): frames submitted without waiting and copied out on the
// sink's thread are the bytes of frames rendered and waited for; more frames than read-back
// slots, with the displacement changing between them, keep their order and their own state;
// a sink that fails reports its error to the next call and never leaves a slot taken (no hang);
// frames drawn from the GPU solver's buffers while its advance still runs show where it ended;
// the measurement switches ($PHYXEL_FRAME_DRAW, $PHYXEL_FRAME_COPY "0") hand the sink nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "render/frame_queue.h"
#include "render/sample_shapes.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

class FrameQueueTest : public gpu::VulkanTest {};

// Frame k's displacement: the sphere squashed by 2 % per frame along z.
std::vector<Vec3> squashed(const PhyxelSet& set, int k) {
  std::vector<Vec3> u(set.size());
  for (size_t i = 0; i < set.size(); ++i) u[i] = Vec3(0, 0, -0.02 * k * set.rest[i].z());
  return u;
}

std::string frame_file(int k) {
  std::string name = "f";  // appended (GCC 12 warns wrongly about "f" + std::string)
  name += std::to_string(k);
  name += ".png";
  return name;
}

TEST_F(FrameQueueTest, QueuedFramesAreTheBytesOfWaitedFramesInTheirOrder) {
  const PhyxelSet set = lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006);
  const RgbaImage texture = procedural_tissue_texture(64);
  // The queue's renderer and a reference one (same table: the same bytes when waited for).
  test::RenderedSet queued(ctx(), set, texture);
  test::RenderedSet reference(ctx(), set, texture);
  const FrameSetup setup =
      test::setup_for(test::camera_at(Vec3(0, -0.08, 0.02), Vec3::Zero(), Vec3::UnitZ()), 96, 64);
  const std::filesystem::path dir = test::test_out_dir() / "frame_queue";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  constexpr int kFrames = 5;  // more than the read-back slots
  {
    FrameSink sink(dir, true, nullptr);
    FrameQueue queue(ctx(), *queued.renderer, sink);
    // On a GPU with copy engines the frames cross on the transfer queue (not on lavapipe).
    EXPECT_EQ(queue.copies_on_transfer_queue(), ctx().transfer_queue() != VK_NULL_HANDLE);
    for (int k = 0; k < kFrames; ++k) {
      queue.drain();  // before the host inputs change under the frame in flight
      queued.inputs->set_displacement(squashed(set, k));
      const std::string name = frame_file(k);
      queue.submit(queued.inputs->inputs(), setup, name, k);
      EXPECT_TRUE(queue.in_flight());
    }
    queue.drain();
    EXPECT_FALSE(queue.in_flight());
    sink.flush();
  }
  RgbaImage previous;
  for (int k = 0; k < kFrames; ++k) {
    const std::vector<Vec3> u = squashed(set, k);
    const RgbaImage expected = reference.render(setup, &u);
    const std::string name = frame_file(k);
    const RgbaImage got = load_image(dir / name, name);
    ASSERT_EQ(got.width, expected.width);
    ASSERT_EQ(got.height, expected.height);
    EXPECT_EQ(got.pixels, expected.pixels) << name;
    if (k > 0) {
      EXPECT_NE(got.pixels, previous.pixels) << name << ": the state changed";
    }
    previous = got;
  }
}

TEST_F(FrameQueueTest, TheMeasurementSwitchesDrawLessAndWriteNothing) {
  const PhyxelSet set = lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006);
  test::RenderedSet rendered(ctx(), set, procedural_tissue_texture(64));
  const FrameSetup setup =
      test::setup_for(test::camera_at(Vec3(0, -0.08, 0.02), Vec3::Zero(), Vec3::UnitZ()), 96, 64);
  for (const char* name : {"PHYXEL_FRAME_DRAW", "PHYXEL_FRAME_COPY"}) {
    SCOPED_TRACE(name);
    const std::filesystem::path dir = test::test_out_dir() / "frame_queue_switch";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    ::setenv(name, "0", 1);
    {
      FrameSink sink(dir, true, nullptr);
      FrameQueue queue(ctx(), *rendered.renderer, sink);
      ::unsetenv(name);
      EXPECT_FALSE(queue.copies_on_transfer_queue() && std::string(name) == "PHYXEL_FRAME_COPY");
      for (int k = 0; k < 3; ++k) {  // more than the read-back slots: none stays taken
        queue.drain();
        rendered.inputs->set_displacement(squashed(set, k));
        queue.submit(rendered.inputs->inputs(), setup, frame_file(k), k);
      }
      queue.drain();
      sink.flush();
    }
    EXPECT_TRUE(std::filesystem::is_empty(dir));
    rendered.renderer->set_readback(true);
  }
  // Without them, the renderer reads back again.
  EXPECT_EQ(rendered.render(setup, nullptr).width, setup.frame_width());
}

TEST_F(FrameQueueTest, ASinkThatFailsReportsItAndFreesItsSlots) {
  const PhyxelSet set = lattice_sphere(Vec3::Zero(), 0.01, 0.002, 0.006);
  test::RenderedSet s(ctx(), set, procedural_tissue_texture(64));
  const FrameSetup setup =
      test::setup_for(test::camera_at(Vec3(0, -0.08, 0), Vec3::Zero(), Vec3::UnitZ()), 48, 32);
  s.inputs->set_displacement(std::vector<Vec3>(set.size(), Vec3::Zero()));
  // PNG files into a folder that does not exist: the first frame's write fails.
  FrameSink sink(test::test_out_dir() / "frame_queue_missing" / "no" / "such", true, nullptr);
  FrameQueue queue(ctx(), *s.renderer, sink);
  int thrown = 0;
  for (int k = 0; k < 8 && thrown == 0; ++k) {
    try {
      queue.submit(s.inputs->inputs(), setup, "f.png", k);
      queue.drain();
      sink.flush();  // waits for the write: its failure comes back here or at the next push
    } catch (const std::runtime_error& e) {
      ++thrown;
      EXPECT_NE(std::string(e.what()).find("f.png"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(thrown, 1);
  // The failed frames' slots are free again: more frames than slots are still drawn (each
  // failing to be written in turn) rather than waiting forever for a slot.
  int failures = 0;
  for (int k = 0; k < 4; ++k) {
    try {
      queue.submit(s.inputs->inputs(), setup, "g.png", k);
      queue.drain();
      sink.flush();
    } catch (const std::runtime_error&) {
      ++failures;
    }
  }
  EXPECT_EQ(failures, 4);
}

// As `phyxel run` and `phyxel bench --render` draw a GPU run's frames: the advance returns with
// its last submission running, the frame is recorded and submitted behind it on the same queue.
// Each frame is the one drawn from a solver that finished the same advances.
TEST_F(FrameQueueTest, FramesQueuedBehindAnAdvanceInFlightShowTheAdvancedState) {
  PhyxelSet set = lattice_sphere(Vec3::Zero(), 0.012, 0.002, 0.006);
  for (size_t i = 0; i < set.size(); ++i)
    set.initial_velocity[i] = Vec3(0, 0, -2 * set.rest[i].z());
  const double dt = plan_time_step(Scene{}, set).dt_stable;
  const RgbaImage texture = procedural_tissue_texture(64);
  test::RenderedSet queued(ctx(), set, texture);
  test::RenderedSet reference(ctx(), set, texture);
  const FrameSetup setup =
      test::setup_for(test::camera_at(Vec3(0, -0.08, 0.02), Vec3::Zero(), Vec3::UnitZ()), 96, 64);
  const std::filesystem::path dir = test::test_out_dir() / "frame_queue_in_flight";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  constexpr int kFrames = 4;
  constexpr int64_t kSteps = 30;
  {
    gpu::GpuSolver solver(ctx(), set, Vec3::Zero());
    FrameSink sink(dir, true, nullptr);
    FrameQueue queue(ctx(), *queued.renderer, sink);
    for (int k = 0; k < kFrames; ++k) {
      solver.advance(kSteps, dt);
      EXPECT_TRUE(solver.advance_in_flight()) << k;
      queue.submit(solver.buffers(), setup, frame_file(k), k);
    }
    queue.drain();
    sink.flush();
  }
  gpu::GpuSolver finished(ctx(), set, Vec3::Zero());
  RgbaImage previous;
  for (int k = 0; k < kFrames; ++k) {
    finished.advance(kSteps, dt);
    finished.finish();
    const RgbaImage expected = reference.renderer->render(finished.buffers(), setup);
    const std::string name = frame_file(k);
    const RgbaImage got = load_image(dir / name, name);
    ASSERT_EQ(got.pixels.size(), expected.pixels.size());
    EXPECT_EQ(got.pixels, expected.pixels) << name;
    if (k > 0) {
      EXPECT_NE(got.pixels, previous.pixels) << name << ": the sphere moved";
    }
    previous = got;
  }
}

}  // namespace
}  // namespace phyxel::render
