// The video texture (render.video_texture, the paper's section VI): the synthetic clip decodes
// back to the frames the generator wrote, the texture gives the frame of the simulated time
// exactly and loops, a video-textured sphere on lavapipe at two simulated times (goldens), and a
// missing or undecodable video is refused naming the file before anything runs.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>

#include "bench/render_bench.h"
#include "engine/sampling/phyxel_set.h"
#include "render/frame_output.h"
#include "render/sample_shapes.h"
#include "render/video_clip.h"
#include "render/video_decoder.h"
#include "render/video_loop.h"
#include "render/video_texture.h"
#include "render/video_writer.h"
#include "render/vk_images.h"
#include "tests/render/render_test_util.h"

namespace phyxel::render {
namespace {

namespace fs = std::filesystem;

// The generator's clip, small: 96 x 64, 12 frames at 30 frames/s (written once per run).
VideoClipOptions small_clip() {
  VideoClipOptions o;
  o.width = 96;
  o.height = 64;
  o.frames = 12;
  return o;
}

// A file removed when the process exits normally.
struct ProcessFile {
  fs::path path;
  ~ProcessFile() {
    std::error_code ec;
    fs::remove(path, ec);
  }
};

const fs::path& clip_file() {
  static const ProcessFile file = [] {
    // One file per process: ctest runs this binary's tests in parallel processes, and one
    // rewriting a shared clip while another decodes it fails the other. Removed at exit, so
    // runs do not pile them up in the test output.
    const fs::path f =
        test::test_out_dir() / ("video_texture_clip_" + std::to_string(::getpid()) + ".mp4");
    write_pulsing_tissue_clip(f, small_clip());
    return ProcessFile{f};
  }();
  return file.path;
}

double psnr(const RgbaImage& a, const RgbaImage& b) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) {
    if (i % 4 == 3) continue;
    const double d = double(a.pixels[i]) - double(b.pixels[i]);
    sum += d * d;
    ++n;
  }
  const double mse = sum / double(n);
  return mse == 0 ? 99 : 10 * std::log10(255.0 * 255.0 / mse);
}

TEST(VideoDecoder, DecodedFramesEqualTheFramesTheGeneratorWrote) {
  VideoDecoder decoder(clip_file());
  EXPECT_EQ(decoder.width(), 96u);
  EXPECT_EQ(decoder.height(), 64u);
  EXPECT_NEAR(decoder.fps(), 30, 1e-9);
  RgbaImage frame;
  int count = 0;
  double worst = 99;
  while (decoder.next(&frame)) {
    const double p = psnr(frame, pulsing_tissue_frame(small_clip(), count));
    worst = std::min(worst, p);
    EXPECT_GE(p, 40) << "frame " << count;
    ++count;
  }
  EXPECT_EQ(count, 12);
  std::printf("decoded frames: PSNR >= %.1f dB\n", worst);
  decoder.rewind();
  ASSERT_TRUE(decoder.next(&frame));
  EXPECT_GE(psnr(frame, pulsing_tissue_frame(small_clip(), 0)), 40) << "after rewind()";
  // Scaled down to max_side, aspect kept.
  VideoDecoder half(clip_file(), 48);
  EXPECT_EQ(half.width(), 48u);
  EXPECT_EQ(half.height(), 32u);
}

TEST(VideoDecoder, AnotherContainerAndCodecFfv1InMatroska) {
  const fs::path file = test::test_out_dir() / "video_texture_clip.mkv";
  const VideoClipOptions o = small_clip();
  {
    VideoWriter writer(file, o.width, o.height, o.fps, VideoEncoding::Ffv1);
    for (int k = 0; k < 3; ++k) writer.add(pulsing_tissue_frame(o, k), k);
    writer.finish();
  }
  VideoDecoder decoder(file);
  RgbaImage frame;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(decoder.next(&frame)) << k;
    EXPECT_EQ(frame.pixels, pulsing_tissue_frame(o, k).pixels) << "FFV1 in RGB is lossless";
  }
  EXPECT_FALSE(decoder.next(&frame));
}

TEST(VideoDecoder, MissingOrUndecodableFilesNameTheFile) {
  const fs::path garbage = test::test_out_dir() / "not_a_video.mp4";
  std::ofstream(garbage) << "this is no video, just text\n";
  const fs::path missing = test::test_out_dir() / "no_such_video.mp4";
  for (const fs::path& f : {garbage, missing}) {
    try {
      VideoDecoder d(f);
      ADD_FAILURE() << f << " opened";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(f.string() + ": cannot decode the video"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(VideoTexture, GivesTheFrameOfTheSimulatedTimeAndLoops) {
  VideoDecoder decoder(clip_file());
  std::vector<RgbaImage> frames(12);
  for (RgbaImage& f : frames) ASSERT_TRUE(decoder.next(&f));

  VideoTexture plain(clip_file());
  EXPECT_EQ(plain.frames(), 12);
  EXPECT_EQ(plain.loop_frames(), 12);
  EXPECT_EQ(plain.frame_index(0.5 / 30), 0);
  EXPECT_EQ(plain.frame_index(1.0 / 30), 1) << "a frame's own time shows it";
  const double times[] = {0, 3.5 / 30, 11.2 / 30, 14.0 / 30, 2.0 / 30, 40.0 / 30};
  const int content[] = {0, 3, 11, 2, 2, 4};  // 14 and 40 loop to 2 and 4; 2 goes back in time
  for (size_t i = 0; i < std::size(times); ++i) {
    const std::vector<RgbaImage>* levels = plain.frame_at(times[i]);
    ASSERT_NE(levels, nullptr) << i;
    EXPECT_EQ((*levels)[0].pixels, frames[size_t(content[i])].pixels) << "time " << times[i];
    EXPECT_EQ(levels->back().width, 1u) << "the whole mip chain";
  }
  EXPECT_EQ(plain.frame_at(40.5 / 30), nullptr) << "the same frame again: nothing to upload";

  // Loop blend B = 3: L = 9 frames, the first 3 blended with frames 9, 10, 11 (eq 32).
  VideoTextureOptions options;
  options.loop_blend = 3;
  VideoTexture looped(clip_file(), options);
  EXPECT_EQ(looped.loop_frames(), 9);
  const std::vector<RgbaImage> loop = loop_clip(frames, 3);
  for (int k : {0, 2, 5, 8, 9, 10}) {
    const std::vector<RgbaImage>* levels = looped.frame_at(k / 30.0);
    ASSERT_NE(levels, nullptr) << k;
    EXPECT_EQ((*levels)[0].pixels, loop[size_t(k % 9)].pixels) << "frame " << k;
  }
  // The viewer's call never waits, and hands out frames up to the time asked for only.
  VideoTexture live(clip_file());
  const std::vector<RgbaImage>* newest = nullptr;
  for (int tries = 0; tries < 2000 && newest == nullptr; ++tries) {
    newest = live.newest(5.0 / 30);
    if (newest == nullptr) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_NE(newest, nullptr);
  EXPECT_LE(live.current_index(), 5);
  EXPECT_GT(live.timing().frames, 0);
}

class VideoTextureRender : public gpu::VulkanTest {};

// A sphere textured with the clip at two simulated times, through SplatRenderer::set_texture
// (the frame's upload recorded into the frame): goldens, the two differ, and each equals the
// sphere built with that frame as a static texture.
TEST_F(VideoTextureRender, VideoTexturedSphereAtTwoSimulatedTimes) {
  VideoTexture video(clip_file());
  const RgbaImage first = (*video.frame_at(0))[0];
  test::RenderedSet s(ctx(), lattice_sphere(Vec3::Zero(), 0.02, 0.002, 0.006), first);
  const Camera cam = test::camera_at(Vec3(0, -0.03, 0.09), Vec3::Zero(), Vec3::UnitZ(), 35);
  const FrameSetup setup = test::setup_for(cam, 128, 128);
  RgbaImage images[2];
  const double times[2] = {2.0 / 30, 7.0 / 30};  // systole and relaxation
  for (int i = 0; i < 2; ++i) {
    const std::vector<RgbaImage>* levels = video.frame_at(times[i]);
    ASSERT_NE(levels, nullptr);
    s.renderer->set_texture(*levels);
    images[i] = s.render(setup);
    test::RenderedSet still(ctx(), s.set, (*levels)[0]);
    EXPECT_EQ(still.render(setup).pixels, images[i].pixels) << "time " << times[i];
  }
  size_t changed = 0, covered = 0;
  for (uint32_t y = 0; y < 128; ++y)
    for (uint32_t x = 0; x < 128; ++x) {
      if (test::is_background(images[0].at(x, y))) continue;
      ++covered;
      int d = 0;
      for (int c = 0; c < 3; ++c)
        d = std::max(d, std::abs(images[0].at(x, y)[c] - images[1].at(x, y)[c]));
      changed += d > 8;
    }
  EXPECT_GT(covered, 128u * 128 / 4);
  EXPECT_GT(changed, covered / 20) << "the texture moves between the two times";
  test::expect_matches_golden(images[0], "video_texture_sphere_t2");
  test::expect_matches_golden(images[1], "video_texture_sphere_t7");
}

TEST_F(VideoTextureRender, BenchRowWithTheVideoTextureAndTheEnvironment) {
  bench::RenderBenchOptions options;
  options.surfels = 1500;
  options.eye_width = 64;
  options.height = 48;
  options.frames = 2;
  options.video_texture = true;
  const bench::RenderBenchResult r = bench::bench_render(ctx(), options);
  EXPECT_GT(r.median_frame_s, 0.0);
  EXPECT_GT(r.video_decode_s, 0.0);
  EXPECT_GT(r.video_process_s, 0.0);
}

TEST(VideoTextureScene, MissingOrUndecodableVideoIsRefusedNamingTheFile) {
  const fs::path dir = test::test_out_dir() / "video_texture_scene";
  fs::create_directories(dir);
  fs::copy_file(clip_file(), dir / "clip.mp4", fs::copy_options::overwrite_existing);
  std::ofstream(dir / "broken.mp4") << "not a video\n";
  const std::string head = R"({"simulation": {"dt": 1e-4, "steps": 1}, "objects": [{"name": "b",
      "shape": {"type": "box", "min": [0, 0, 0], "max": [0.01, 0.01, 0.01]}, "spacing": 0.0025,
      "material": {"young": 1000, "poisson": 0.3, "density": 1000}}], "render": )";
  const Scene scene =
      parse_scene(head + R"({"mode": "mono", "video_texture": {"file": "clip.mp4", "loop_blend": 4,
               "repair_specular": true}}})",
                  dir / "s.json");
  EXPECT_EQ(scene.render.video_texture.file, dir / "clip.mp4");
  EXPECT_EQ(scene.render.video_texture.loop_blend, 4);
  EXPECT_TRUE(scene.render.video_texture.repair_specular);
  EXPECT_EQ(parse_scene(head + R"({"video_texture": "clip.mp4"}})", dir / "p.json")
                .render.video_texture.file,
            dir / "clip.mp4");
  try {
    parse_scene(head + R"({"video_texture": "gone.mp4"}})", dir / "m.json");
    ADD_FAILURE() << "a missing video was accepted";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("render.video_texture"), std::string::npos) << what;
    EXPECT_NE(what.find("video file \"" + (dir / "gone.mp4").string() + "\" does not exist"),
              std::string::npos)
        << what;
  }
  EXPECT_THROW(parse_scene(head + R"({"video_texture": {"file": "clip.mp4", "loop_blend": -1}}})",
                           dir / "b.json"),
               SceneError);
  // Undecodable: refused when the frame writer opens it, before any context or frame.
  const Scene broken =
      parse_scene(head + R"({"mode": "mono", "video_texture": "broken.mp4"}})", dir / "u.json");
  const PhyxelSet set = sample_scene(broken);
  FrameWriterOptions o;
  o.out_dir = dir;
  try {
    FrameWriter writer(broken, set, o);
    ADD_FAILURE() << "an undecodable video was accepted";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("u.json: render.video_texture: " + (dir / "broken.mp4").string() +
                        ": cannot decode the video"),
              std::string::npos)
        << what;
  }
}

// The command line: a short CPU run of a block with the clip as its texture, and the same
// scene with a file that is no video, refused before the first step.
TEST(VideoTextureCommand, RunShowsTheVideoAndRefusesAnUndecodableOneBeforeItStarts) {
  const fs::path dir = test::test_out_dir() / "video_texture_run";
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(clip_file(), dir / "clip.mp4");
  std::ofstream(dir / "broken.mp4") << "not a video\n";
  // Frames every 350 steps of 1e-4 s: clip frames 0, 1 and 2 (30 frames/s).
  auto scene = [&](const std::string& name, const std::string& video) {
    std::ofstream(dir / name) << R"({"simulation": {"dt": 1e-4, "steps": 700},
      "objects": [{"name": "b", "shape": {"type": "box", "min": [0, 0, 0],
        "max": [0.02, 0.01, 0.01]}, "spacing": 0.0025,
        "material": {"young": 5000, "poisson": 0.3, "density": 1000},
        "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}]}],
      "render": {"mode": "mono", "width": 64, "height": 48, "every": 350,
                 "video_texture": ")" +
                                     video + R"("}})";
    return (dir / name).string();
  };
  const std::string phyxel = std::string(PHYXEL_BINARY_DIR) + "/app/phyxel run ";
  const fs::path good = dir / "good", bad = dir / "bad";
  ASSERT_EQ(std::system((phyxel + scene("good.json", "clip.mp4") + " --quiet --out " +
                         good.string() + " 2> " + (dir / "good.err").string())
                            .c_str()),
            0);
  for (const char* f : {"frame_000000.png", "frame_000350.png", "frame_000700.png"})
    EXPECT_TRUE(fs::exists(good / f)) << f;
  const int status = std::system((phyxel + scene("bad.json", "broken.mp4") + " --quiet --out " +
                                  bad.string() + " 2> " + (dir / "bad.err").string())
                                     .c_str());
  EXPECT_NE(status, 0);
  std::ifstream in(dir / "bad.err");
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.find((dir / "bad.json").string() + ": render.video_texture: " +
                      (dir / "broken.mp4").string() + ": cannot decode the video ("),
            0u)
      << line;
  EXPECT_FALSE(fs::exists(bad / "frame_000000.png")) << "a frame was drawn";
  EXPECT_FALSE(fs::exists(bad / "summary.json")) << "the run started";
}

}  // namespace
}  // namespace phyxel::render
