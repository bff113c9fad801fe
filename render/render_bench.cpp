#include "render/render_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "engine/neighbours.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"

namespace phyxel::render {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
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

  gpu::Recorder rec(ctx, "render bench");
  gpu::PassTimer timer(ctx);
  std::vector<double> frame_s;
  std::vector<std::vector<double>> pass_ns;
  std::vector<std::string> names;
  for (int f = -1; f < result.frames; ++f) {  // frame -1: warm-up
    const auto start = std::chrono::steady_clock::now();
    timer.reset(rec);
    renderer.record(rec, inputs.inputs(), setup, &timer);
    rec.submit_and_wait();
    const RgbaImage image = renderer.read_frame();
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (f < 0 || image.pixels.empty()) continue;
    frame_s.push_back(s);
    const std::vector<gpu::PassTime> passes = timer.results();
    pass_ns.resize(passes.size());
    names.resize(passes.size());
    for (size_t p = 0; p < passes.size(); ++p) {
      names[p] = passes[p].name;
      pass_ns[p].push_back(passes[p].ns);
    }
  }
  result.median_frame_s = median(frame_s);
  result.splats_per_s =
      result.median_frame_s > 0 ? double(result.surfels) * result.eyes / result.median_frame_s : 0;
  for (size_t p = 0; p < names.size(); ++p) {
    result.median_passes.push_back({names[p], median(pass_ns[p])});
  }
  return result;
}

}  // namespace phyxel::render
