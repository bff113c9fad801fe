// phyxel bench --render: splat rendering speed (render/render_bench.h), mono or stereo, for a
// list of surfel counts on one Vulkan device, and what rendering at 60 frames/s costs the GPU
// solver's step rate on the same shell (--no-solver skips that); then the last size again with
// the video texture and the environment on, and the rate of --video's encoder at the frames'
// size (--no-video-texture skips both). With --scene
// FILE: that scene's frames at rest, with and without its backdrop (start-up and frame time).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>

#include "bench/benches.h"
#include "bench/render_bench.h"
#include "bench/timing.h"
#include "engine/sampling/phyxel_set.h"
#include "engine/solver/neighbours.h"
#include "render/frame_output.h"
#include "render/video_clip.h"
#include "render/video_writer.h"
#include "render/viewer_controls.h"
#include "render/yuv_convert.h"

namespace phyxel::bench {

namespace {

// phyxel bench --render --scene FILE: the frames of a scene's rest state, as `phyxel run`
// renders them, with the scene's backdrop and without it: the renderer's start-up (surfel
// table, texture, environment, backdrop baked and uploaded), the median frame time, and the
// median while the view turns every frame (the viewer's drag).
int bench_render_scene(const std::string& file, const std::string& device, int64_t width,
                       int64_t height, bool mono, int64_t frames, const std::string& json_file) {
  gpu::ContextOptions context;
  context.device = device;
  gpu::Context ctx(context);
  Scene scene = load_scene(file);
  scene.render.width = static_cast<int>(width);
  scene.render.height = static_cast<int>(height);
  const PhyxelSet set = sample_scene(scene);
  const NeighbourLists neighbours = find_rest_neighbours(set);
  const std::vector<Vec3> rest(set.size(), Vec3::Zero());
  std::printf("%s: %s, %s %lldx%lld per eye, %zu phyxels\n%10s %9s %9s %12s %12s %12s\n",
              ctx.info().name.c_str(), file.c_str(), mono ? "mono" : "stereo",
              static_cast<long long>(width), static_cast<long long>(height), set.size(), "backdrop",
              "splats", "start s", "first ms", "frame ms", "orbit ms");
  nlohmann::json rows = nlohmann::json::array();
  const std::vector<BackdropItem> backdrop = scene.render.backdrop;
  for (const bool with : {false, true}) {
    if (with && backdrop.empty()) break;
    scene.render.backdrop = with ? backdrop : std::vector<BackdropItem>{};
    const auto t0 = std::chrono::steady_clock::now();
    render::FrameWriter writer(
        scene, set, {mono ? RenderSettings::Mode::Mono : RenderSettings::Mode::Stereo, {}}, &ctx);
    render::HostInputs host(ctx, set, neighbours);
    host.set_displacement(rest);
    const double start = seconds_since(t0);
    const auto t1 = std::chrono::steady_clock::now();
    writer.render(host.inputs());  // the first frame draws the backdrop's layer too
    const double first = seconds_since(t1);
    const auto render_frame = [&] { writer.render(host.inputs()); };
    const double frame = time_repeats(render_frame, frames).median;
    // As the viewer while its camera is dragged round: a new view every frame (0.5 degrees of
    // yaw), so the backdrop's layer is drawn anew each time (the turn timed apart).
    render::Orbit orbit(writer.camera());
    const auto turn = [&] {
      orbit.yaw += 0.5 * std::numbers::pi / 180;
      writer.set_setup(render::make_frame_setup(
          orbit.camera(writer.camera()), scene.render,
          mono ? RenderSettings::Mode::Mono : RenderSettings::Mode::Stereo));
    };
    const double orbiting = time_interleaved({turn, render_frame}, frames)[1].median;
    std::printf("%10s %9u %9.3f %12.1f %12.1f %12.1f\n", with ? "yes" : "no",
                writer.renderer().backdrop_count(), start, first * 1e3, frame * 1e3,
                orbiting * 1e3);
    std::fflush(stdout);
    rows.push_back({{"device", ctx.info().name},
                    {"scene", file},
                    {"backdrop", with},
                    {"backdrop_splats", writer.renderer().backdrop_count()},
                    {"surfels", writer.renderer().surfel_count()},
                    {"startup_s", start},
                    {"first_frame_ms", first * 1e3},
                    {"median_frame_ms", frame * 1e3},
                    {"median_orbit_frame_ms", orbiting * 1e3},
                    {"frames", frames}});
  }
  write_json_file(json_file, rows);
  return 0;
}

// `--video`'s encoder alone (VideoWriter: H.264 in MP4, on the calling thread as on the writer
// thread of a run): `frames` frames of the synthetic surgery clip at the frames' size (both eyes
// side by side in stereo) into a temporary file, timed from opening the file to its index
// written. Also times the RGBA -> YUV 4:2:0 conversion alone (`convert_ms`, per frame).
struct EncodeRate {
  double frames_per_s = 0, convert_ms = 0;
};
EncodeRate bench_video_encode(uint32_t width, uint32_t height, int frames,
                              const std::string& preset) {
  render::VideoClipOptions clip;
  clip.width = width;
  clip.height = height;
  std::vector<render::RgbaImage> images;  // made before the clock starts
  for (int k = 0; k < 8; ++k) images.push_back(render::pulsing_tissue_frame(clip, k));
  const std::filesystem::path file = std::filesystem::temp_directory_path() /
                                     ("phyxel_bench_encode_" + std::to_string(::getpid()) + ".mp4");
  EncodeRate rate;
  {
    const uint32_t w = (width + 1) / 2 * 2, h = (height + 1) / 2 * 2;
    std::vector<uint8_t> y(size_t(w) * h), u(size_t(w / 2) * (h / 2)), v(u.size());
    const render::YuvPlanes planes{
        {y.data(), u.data(), v.data()}, {int(w), int(w / 2), int(w / 2)}, w, h};
    const auto start = std::chrono::steady_clock::now();
    for (const render::RgbaImage& image : images) render::rgba_to_yuv420(image, planes);
    rate.convert_ms = 1e3 * seconds_since(start) / double(images.size());
  }
  const auto start = std::chrono::steady_clock::now();
  {
    render::VideoWriter video(file, width, height, 60, render::VideoEncoding::H264, preset);
    for (int k = 0; k < frames; ++k) video.add(images[size_t(k) % images.size()], k);
    video.finish();
  }
  const double seconds = seconds_since(start);
  std::error_code ec;
  std::filesystem::remove(file, ec);
  rate.frames_per_s = frames / std::max(seconds, 1e-30);
  return rate;
}

}  // namespace

int bench_render_command(const Args& args) {
  OptionParser opts("bench", args);
  opts.flag("--render");
  const std::string scene_file = opts.value("--scene", "");
  const std::string device = opts.value("--device", "gpu");
  const std::string sizes = opts.value("--surfels", "10000,100000,1000000");
  const int64_t width = opts.integer("--width", 1920, 16, 16384);
  const int64_t height = opts.integer("--height", 1080, 16, 16384);
  const bool mono = opts.flag("--mono");
  const int64_t frames = opts.integer("--frames", 10, 1, 10000);
  const std::string json_file = opts.value("--json", "");
  const bool with_solver = !opts.flag("--no-solver");
  const bool no_video = opts.flag("--no-video-texture");
  const std::string preset = opts.value("--video-preset", render::kVideoPreset);
  opts.finish();
  if (!scene_file.empty()) {
    return bench_render_scene(scene_file, device, width, height, mono, frames, json_file);
  }
  gpu::ContextOptions context;
  context.device = device;
  gpu::Context ctx(context);
  nlohmann::json rows = nlohmann::json::array();
  std::printf("%s: %s %lldx%lld per eye\n%10s %9s %9s %9s %12s  %s\n", ctx.info().name.c_str(),
              mono ? "mono" : "stereo", static_cast<long long>(width),
              static_cast<long long>(height), "surfels", "GPU ms", "copy ms", "host ms", "splats/s",
              "GPU passes (ms)");
  // One row: `item` surfels, with the video texture and the environment when `video`.
  auto bench_one = [&](const std::string& item, bool video) {
    RenderBenchOptions o;
    o.surfels = static_cast<uint32_t>(std::stoul(item));
    o.eye_width = static_cast<uint32_t>(width);
    o.height = static_cast<uint32_t>(height);
    o.stereo = !mono;
    o.frames = static_cast<int>(frames);
    o.with_solver = with_solver && !video;
    o.video_texture = video;
    const RenderBenchResult r = bench_render(ctx, o);
    std::string passes;
    nlohmann::json pass_json = nlohmann::json::object();
    for (const gpu::PassTime& p : r.median_passes) {
      char text[96];
      std::snprintf(text, sizeof text, "%s%s %.3f", passes.empty() ? "" : ", ", p.name.c_str(),
                    p.ns * 1e-6);
      passes += text;
      pass_json[p.name] = p.ns * 1e-6;
    }
    std::printf("%10u %9.3f %9.3f %9.3f %12.4g  %s\n", r.surfels, r.median_gpu_s * 1e3,
                r.median_readback_s * 1e3, r.median_frame_s * 1e3, r.splats_per_s, passes.c_str());
    if (video) {
      std::printf(
          "%10s with the video texture and the environment (a new clip frame every frame; "
          "its thread: decode %.3f ms, repair + blend + mips %.3f ms per clip frame)\n",
          "", r.video_decode_s * 1e3, r.video_process_s * 1e3);
    }
    if (o.with_solver) {
      std::printf(
          "%10s solver on the same %u phyxels: %.4g steps/s alone, %.4g steps/s (%.1f %%) "
          "with a frame every %lld steps (%.1f frames/s, GPU %.3f ms per frame)\n",
          "", r.phyxels, r.solver_steps_per_s, r.solver_steps_per_s_rendering,
          100 * r.solver_steps_per_s_rendering / std::max(r.solver_steps_per_s, 1e-30),
          static_cast<long long>(r.steps_per_frame), r.frames_per_s_rendering,
          r.solver_frame_gpu_s * 1e3);
    }
    std::fflush(stdout);
    rows.push_back({{"device", r.device},
                    {"surfels", r.surfels},
                    {"eyes", r.eyes},
                    {"frame_width", r.frame_width},
                    {"frame_height", r.frame_height},
                    {"median_frame_ms", r.median_frame_s * 1e3},
                    {"median_gpu_ms", r.median_gpu_s * 1e3},
                    {"median_readback_ms", r.median_readback_s * 1e3},
                    {"phyxels", r.phyxels},
                    {"solver_steps_per_s", r.solver_steps_per_s},
                    {"solver_steps_per_s_rendering", r.solver_steps_per_s_rendering},
                    {"steps_per_frame", r.steps_per_frame},
                    {"frames_per_s_rendering", r.frames_per_s_rendering},
                    {"solver_frame_gpu_ms", r.solver_frame_gpu_s * 1e3},
                    {"splats_per_s", r.splats_per_s},
                    {"gpu_pass_ms", pass_json},
                    {"frames", r.frames},
                    {"video_texture", video},
                    {"video_decode_ms", r.video_decode_s * 1e3},
                    {"video_process_ms", r.video_process_s * 1e3}});
  };
  std::stringstream ss(sizes);
  std::string last;
  for (std::string item; std::getline(ss, item, ',');) bench_one(last = item, false);
  // And the last size again with the video texture on and the environment (docs/performance.md).
  if (!last.empty() && !no_video) bench_one(last, true);
  if (!no_video) {  // and what --video's encoder sustains at this frame size
    const uint32_t video_width = static_cast<uint32_t>((mono ? 1 : 2) * width);
    const int encoded = static_cast<int>(std::max<int64_t>(frames, 30));
    const EncodeRate rate =
        bench_video_encode(video_width, static_cast<uint32_t>(height), encoded, preset);
    std::printf(
        "%10s --video encodes %ux%lld frames (H.264, libx264) at %.1f frames/s of wall "
        "time (%d frames of the synthetic clip; RGBA -> YUV %.2f ms a frame)\n",
        "", video_width, static_cast<long long>(height), rate.frames_per_s, encoded,
        rate.convert_ms);
    rows.push_back({{"video_encode_width", video_width},
                    {"video_encode_height", height},
                    {"video_encode_frames", encoded},
                    {"video_preset", preset},
                    {"video_encode_frames_per_s", rate.frames_per_s},
                    {"video_convert_ms", rate.convert_ms}});
  }
  write_json_file(json_file, rows);
  return 0;
}

}  // namespace phyxel::bench
