#include "bench/render_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "bench/timing.h"
#include "compute/gpu_solver.h"
#include "engine/run/simulation.h"
#include "engine/solver/neighbours.h"
#include "render/environment_map.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"
#include "render/video_clip.h"
#include "render/video_texture.h"

namespace phyxel::bench {
using namespace phyxel::render;  // the renderer's API throughout
namespace {

// The GPU solver on the shell: steps/s alone, then with a frame rendered from its buffers every
// 1/60 s worth of steps, each frame read back into an image.
void bench_with_solver(gpu::Context& ctx, const PhyxelSet& shell, const SurfelTable& table,
                       const FrameSetup& setup, int frames, RenderBenchResult& result) {
  // The shell breathes (radial velocity 0.5 x/s, free of loads): it deforms and stays in the
  // camera's view however many steps run (under gravity it would fall out of the frame, and
  // frames of an empty view cost less than frames of the shell).
  PhyxelSet set = shell;
  const Vec3 centre = table.bounds.center();
  for (size_t i = 0; i < set.size(); ++i) set.initial_velocity[i] = 0.5 * (set.rest[i] - centre);
  Scene scene;
  const double dt = plan_time_step(scene, set).dt_stable;
  gpu::GpuSolver solver(ctx, set, Vec3::Zero());
  SplatRenderer renderer(ctx, table, procedural_tissue_texture());
  solver.advance(gpu::GpuSolver::kStepsPerSubmit, dt);  // warm-up
  int64_t steps = gpu::GpuSolver::kStepsPerSubmit;
  const auto advance = [&] {
    solver.advance(steps, dt);
    solver.finish();
  };
  // About 0.3 s of stepping per timed repeat.
  while (time_repeats(advance, 1).median <= 0.3 && steps < (int64_t{1} << 24)) steps *= 2;
  result.solver_steps_per_s = double(steps) / time_repeats(advance, 3).median;
  result.steps_per_frame = std::max<int64_t>(1, std::llround(result.solver_steps_per_s / 60));
  renderer.render(solver.buffers(), setup);  // warm-up
  {
    // As a run draws its frames (render/frame_queue.h): each frame submitted without waiting,
    // completed at the next, its pixels copied out (and dropped) on the sink's thread.
    FrameSink sink({}, false, nullptr);
    FrameQueue queue(ctx, renderer, sink);
    const auto start = std::chrono::steady_clock::now();
    for (int f = 0; f < frames; ++f) {
      solver.advance(result.steps_per_frame, dt);
      queue.submit(solver.buffers(), setup, "", f);
    }
    queue.drain();
    sink.flush();
    const double s = seconds_since(start);
    result.solver_steps_per_s_rendering = double(frames * result.steps_per_frame) / s;
    result.frames_per_s_rendering = frames / s;
  }
  // The GPU time of a frame while the solver runs, by timestamps (frames waited for).
  gpu::Recorder rec(ctx, "render bench with solver");
  gpu::PassTimer timer(ctx);
  std::vector<double> gpu_s;
  for (int f = 0; f < std::min(frames, 20); ++f) {
    solver.advance(result.steps_per_frame, dt);
    timer.reset(rec);
    renderer.record(rec, solver.buffers(), setup, &timer);
    rec.submit_and_wait();
    double ns = 0;
    for (const gpu::PassTime& p : timer.results())
      if (p.name != "render readback") ns += p.ns;
    gpu_s.push_back(ns * 1e-9);
  }
  result.solver_frame_gpu_s = median_of(gpu_s);
}

}  // namespace

RenderBenchResult bench_render(gpu::Context& ctx, const RenderBenchOptions& options) {
  // A lattice sphere of radius R (in spacings) has about 0.8 * 4 pi R^2 surface phyxels.
  const double spacing = 0.002;
  const double radius =
      spacing * std::max(3.0, std::sqrt(options.surfels / (4 * std::numbers::pi * 0.8)));
  const PhyxelSet set = lattice_sphere(Vec3::Zero(), radius, spacing, 3 * spacing);
  const NeighbourLists neighbours = find_rest_neighbours(set);
  const SurfelTable table = build_surfel_table(set);
  HostInputs inputs(ctx, set, neighbours);
  SplatRenderer renderer(ctx, table, procedural_tissue_texture());

  RenderSettings settings;
  settings.width = static_cast<int>(options.eye_width);
  settings.height = static_cast<int>(options.height);
  const Camera camera =
      resolve_camera(CameraSettings{}, table.bounds, double(options.eye_width) / options.height);
  std::unique_ptr<VideoTexture> video;
  int64_t video_frame = 0;
  std::filesystem::path clip;
  if (options.video_texture) {
    clip = std::filesystem::temp_directory_path() /
           ("phyxel-bench-clip-" +
            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + ".mp4");
    write_pulsing_tissue_clip(clip, VideoClipOptions{});
    VideoTextureOptions v;
    v.loop_blend = 12;
    v.repair_specular = true;
    video = std::make_unique<VideoTexture>(clip, v);
    std::filesystem::remove(clip);  // open: the decoder keeps reading it
    renderer.set_environment(procedural_operating_field(), environment_basis(camera), 4.0);
  }
  // The clip's next frame for the next frame recorded (waits for the decoding thread).
  auto next_video_frame = [&] {
    if (!video) return;
    const std::vector<RgbaImage>* levels = video->frame_at(double(video_frame++) / video->fps());
    if (levels != nullptr) renderer.set_texture(*levels);
  };
  const FrameSetup setup = make_frame_setup(
      camera, settings, options.stereo ? RenderSettings::Mode::Stereo : RenderSettings::Mode::Mono);

  RenderBenchResult result;
  result.device = ctx.info().name;
  result.surfels = renderer.surfel_count();
  result.phyxels = static_cast<uint32_t>(set.size());
  result.frame_width = setup.frame_width();
  result.frame_height = setup.height;
  result.eyes = setup.eye_count();
  result.frames = std::max(1, options.frames);

  // The GPU lowers its clocks when idle (an H100 idles at a few hundred MHz, and one frame
  // with host work around it does not bring them up: a 1M-surfel frame measured 2.8 ms after
  // one warm-up frame, 1.3 ms after 300): first about 0.5 s of frames back to back.
  gpu::Recorder rec(ctx, "render bench");
  constexpr int kBatch = 8;  // frames per submission while timing the GPU: it never idles
  const auto warm = std::chrono::steady_clock::now();
  do {
    next_video_frame();
    for (int k = 0; k < kBatch; ++k) renderer.record(rec, inputs.inputs(), setup);
    rec.submit_and_wait();
  } while (seconds_since(warm) < 0.5);

  // GPU time: batches of kBatch frames per submission, a timestamp pair around each pass.
  gpu::PassTimer timer(ctx);
  std::vector<double> gpu_s, readback_s;
  std::vector<std::vector<double>> pass_ns;
  std::vector<std::string> names;
  for (int done = 0; done < result.frames;) {
    const int n = std::min(kBatch, result.frames - done);
    timer.reset(rec);
    next_video_frame();  // uploaded in the batch's first frame
    for (int k = 0; k < n; ++k) renderer.record(rec, inputs.inputs(), setup, &timer);
    rec.submit_and_wait();
    done += n;
    const std::vector<gpu::PassTime> passes = timer.results();
    if (passes.empty() || passes.size() % n != 0) continue;  // no timestamps on this queue
    const size_t per_frame = passes.size() / n;
    names.resize(per_frame);
    pass_ns.resize(per_frame);
    for (int k = 0; k < n; ++k) {
      double gpu_ns = 0, readback_ns = 0;
      for (size_t p = 0; p < per_frame; ++p) {
        const gpu::PassTime& t = passes[k * per_frame + p];
        (t.name == "render readback" ? readback_ns : gpu_ns) += t.ns;
        names[p] = t.name;
        pass_ns[p].push_back(t.ns);
      }
      gpu_s.push_back(gpu_ns * 1e-9);
      readback_s.push_back(readback_ns * 1e-9);
    }
  }
  // Host time: one frame at a time, recorded, submitted, waited for and read back into an
  // image, as a caller that writes frames sees it.
  const auto host_frame = [&] {
    next_video_frame();
    renderer.render(inputs.inputs(), setup);
  };
  result.median_frame_s = time_repeats(host_frame, result.frames).median;
  result.median_gpu_s = median_of(gpu_s);
  result.median_readback_s = median_of(readback_s);
  const double per_frame = result.median_gpu_s > 0 ? result.median_gpu_s : result.median_frame_s;
  result.splats_per_s = per_frame > 0 ? double(result.surfels) * result.eyes / per_frame : 0;
  for (size_t p = 0; p < names.size(); ++p) {
    result.median_passes.push_back({names[p], median_of(pass_ns[p])});
  }
  if (video) {
    const VideoTexture::Timing t = video->timing();
    result.video_decode_s = t.decode_s / double(std::max<int64_t>(t.frames, 1));
    result.video_process_s = t.process_s / double(std::max<int64_t>(t.frames, 1));
  }
  if (options.with_solver) bench_with_solver(ctx, set, table, setup, result.frames, result);
  return result;
}

}  // namespace phyxel::bench
