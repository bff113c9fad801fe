// phyxel bench --render: splat rendering speed (render/render_bench.h), mono or stereo, for a
// list of surfel counts on one Vulkan device.
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/bench_extras.h"
#include "app/options.h"
#include "render/render_bench.h"

namespace phyxel::app {

int bench_render_command(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--render");
  const std::string device = opts.value("--device", "gpu");
  const std::string sizes = opts.value("--surfels", "10000,100000,1000000");
  const int64_t width = opts.integer("--width", 1920, 16, 16384);
  const int64_t height = opts.integer("--height", 1080, 16, 16384);
  const bool mono = opts.flag("--mono");
  const int64_t frames = opts.integer("--frames", 10, 1, 10000);
  const std::string json_file = opts.value("--json", "");
  opts.finish();
  gpu::ContextOptions context;
  context.device = device;
  gpu::Context ctx(context);
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%s: %s %lldx%lld per eye\n%10s %14s %16s  %s\n", ctx.info().name.c_str(),
              mono ? "mono" : "stereo", static_cast<long long>(width),
              static_cast<long long>(height), "surfels", "ms per frame", "splats/s",
              "GPU passes (ms)");
  std::stringstream ss(sizes);
  for (std::string item; std::getline(ss, item, ',');) {
    render::RenderBenchOptions o;
    o.surfels = static_cast<uint32_t>(std::stoul(item));
    o.eye_width = static_cast<uint32_t>(width);
    o.height = static_cast<uint32_t>(height);
    o.stereo = !mono;
    o.frames = static_cast<int>(frames);
    const render::RenderBenchResult r = render::bench_render(ctx, o);
    std::string passes;
    nlohmann::json pass_json = nlohmann::json::object();
    for (const gpu::PassTime& p : r.median_passes) {
      char text[96];
      std::snprintf(text, sizeof text, "%s%s %.3f", passes.empty() ? "" : ", ", p.name.c_str(),
                    p.ns * 1e-6);
      passes += text;
      pass_json[p.name] = p.ns * 1e-6;
    }
    std::printf("%10u %14.3f %16.4g  %s\n", r.surfels, r.median_frame_s * 1e3, r.splats_per_s,
                passes.c_str());
    rows.push_back({{"device", r.device},
                    {"surfels", r.surfels},
                    {"eyes", r.eyes},
                    {"frame_width", r.frame_width},
                    {"frame_height", r.frame_height},
                    {"median_frame_ms", r.median_frame_s * 1e3},
                    {"splats_per_s", r.splats_per_s},
                    {"gpu_pass_ms", pass_json},
                    {"frames", r.frames}});
  }
  if (!json_file.empty()) std::ofstream(json_file) << rows.dump(2) << "\n";
  return 0;
}

}  // namespace phyxel::app
