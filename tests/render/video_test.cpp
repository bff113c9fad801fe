// Video output (render/video_writer.h): an MP4 decodes back (libavformat, libavcodec) to the
// frames, size and rate it was given; the writer thread writes PNG files and reports their
// failures; `phyxel run --video` encodes a run and refuses an unwritable path before it starts.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "render/video_writer.h"
#include "tests/render/render_test_util.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}

namespace phyxel::render {
namespace {

struct Decoded {
  int frames = 0, width = 0, height = 0;
  double rate = 0;      // the stream's average frame rate
  int first_luma = -1;  // Y of the first frame's middle pixel
};

Decoded decode(const std::filesystem::path& file) {
  Decoded d;
  AVFormatContext* format = nullptr;
  EXPECT_EQ(avformat_open_input(&format, file.c_str(), nullptr, nullptr), 0) << file;
  if (format == nullptr) return d;
  EXPECT_GE(avformat_find_stream_info(format, nullptr), 0);
  const int index = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  EXPECT_GE(index, 0);
  const AVStream* stream = format->streams[index];
  EXPECT_EQ(stream->codecpar->codec_id, AV_CODEC_ID_H264);
  d.rate = av_q2d(stream->avg_frame_rate);
  const AVCodec* codec = avcodec_find_decoder(stream->codecpar->codec_id);
  AVCodecContext* ctx = avcodec_alloc_context3(codec);
  avcodec_parameters_to_context(ctx, stream->codecpar);
  EXPECT_EQ(avcodec_open2(ctx, codec, nullptr), 0);
  AVPacket* packet = av_packet_alloc();
  AVFrame* frame = av_frame_alloc();
  auto drain = [&] {
    while (avcodec_receive_frame(ctx, frame) == 0) {
      if (d.frames++ == 0) {
        d.width = frame->width;
        d.height = frame->height;
        d.first_luma = frame->data[0][(frame->height / 2) * frame->linesize[0] + frame->width / 2];
      }
    }
  };
  while (av_read_frame(format, packet) >= 0) {
    if (packet->stream_index == index) avcodec_send_packet(ctx, packet);
    av_packet_unref(packet);
    drain();
  }
  avcodec_send_packet(ctx, nullptr);
  drain();
  av_frame_free(&frame);
  av_packet_free(&packet);
  avcodec_free_context(&ctx);
  avformat_close_input(&format);
  return d;
}

RgbaImage grey(uint32_t w, uint32_t h, uint8_t level) {
  RgbaImage image(w, h);
  for (size_t i = 0; i < image.pixels.size(); i += 4)
    image.pixels[i] = image.pixels[i + 1] = image.pixels[i + 2] = level, image.pixels[i + 3] = 255;
  return image;
}

TEST(Video, EncodedMp4DecodesToItsFramesSizeAndRate) {
  const std::filesystem::path file = test::test_out_dir() / "video_test.mp4";
  const double fps = 1.0 / (1000 * 2.4e-4);  // brain_tumour.json: a frame every 0.24 s
  {
    VideoWriter video(file, 96, 64, fps);
    for (int k = 0; k < 12; ++k) video.add(grey(96, 64, uint8_t(200 - 10 * k)), k);
    video.finish();
    EXPECT_EQ(video.frames(), 12);
  }
  const Decoded d = decode(file);
  EXPECT_EQ(d.frames, 12);
  EXPECT_EQ(d.width, 96);
  EXPECT_EQ(d.height, 64);
  EXPECT_NEAR(d.rate, fps, 1e-3);
  // Grey 200 in full range is Y = 16 + 200 x 219 / 255 = 188 in H.264's limited range.
  EXPECT_NEAR(d.first_luma, 188, 3);
}

TEST(Video, OddSidesArePaddedToEvenOnes) {
  const std::filesystem::path file = test::test_out_dir() / "video_odd.mp4";
  {
    VideoWriter video(file, 65, 33, 30);
    for (int k = 0; k < 3; ++k) video.add(grey(65, 33, 90), k);
  }  // the destructor finishes the file
  const Decoded d = decode(file);
  EXPECT_EQ(d.frames, 3);
  EXPECT_EQ(d.width, 66);
  EXPECT_EQ(d.height, 34);
}

TEST(Video, UnwritablePathFailsAtOnceNamingTheFile) {
  try {
    VideoWriter video("/nonexistent-folder/x.mp4", 64, 64, 30);
    ADD_FAILURE() << "opened a video in a folder that does not exist";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-folder/x.mp4: cannot write the video"),
              std::string::npos)
        << e.what();
  }
}

std::string png_name(int k) {
  std::string name = std::to_string(k);
  name += ".png";
  return name;
}

TEST(FrameSinkThread, WritesPngsAndReportsAFailureLater) {
  const std::filesystem::path dir = test::test_out_dir() / "frame_sink";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  {
    FrameSink sink(dir, true, nullptr, 2);
    for (int k = 0; k < 5; ++k) sink.push(png_name(k), grey(8, 8, 50), k);
    sink.finish();
  }
  for (int k = 0; k < 5; ++k) EXPECT_TRUE(std::filesystem::exists(dir / png_name(k))) << k;
  FrameSink sink(dir / "missing", true, nullptr, 2);
  sink.push("a.png", grey(8, 8, 50), 0);
  EXPECT_THROW(sink.finish(), std::runtime_error);
}

// PNG files are encoded by several threads while the video takes the frames in order: every
// file holds its own frame, and the video has them all.
TEST(FrameSinkThread, EncodersWriteEveryFrameItsOwnFileAndTheVideoInOrder) {
  const std::filesystem::path dir = test::test_out_dir() / "frame_sink_encoders";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  constexpr int kFrames = 24;
  {
    auto video = std::make_unique<VideoWriter>(dir / "v.mp4", 32, 16, 24.0);
    FrameSink sink(dir, true, std::move(video), 2, 3);  // three encoders
    for (int k = 0; k < kFrames; ++k)
      sink.push(png_name(k), grey(32, 16, static_cast<uint8_t>(10 * k)), k);
    sink.flush();
    for (int k = 0; k < kFrames; ++k) EXPECT_TRUE(std::filesystem::exists(dir / png_name(k)));
    sink.finish();
  }
  for (int k = 0; k < kFrames; ++k) {
    const RgbaImage image = load_image(dir / png_name(k), png_name(k));
    ASSERT_EQ(image.pixels.size(), size_t(32 * 16 * 4));
    EXPECT_EQ(image.pixels[0], 10 * k) << png_name(k);
  }
  EXPECT_EQ(decode(dir / "v.mp4").frames, kFrames);
}

// The command line: a short CPU run with --video, and an unwritable --video path.
int run(const std::string& args) {
  const std::string cmd = std::string(PHYXEL_BINARY_DIR) + "/app/phyxel run " + args;
  return std::system(cmd.c_str());
}

// A small block, frames of 64 x 48 every 10 steps of 1e-4 s: 1000 frames per simulated second.
std::string small_scene(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "block.json";
  std::ofstream(file) << R"({"simulation": {"dt": 1e-4, "steps": 40, "gravity": [0, 0, -9.81]},
    "objects": [{"name": "b", "shape": {"type": "box", "min": [0, 0, 0], "max": [0.02, 0.01, 0.01]},
      "spacing": 0.0025, "material": {"young": 5000, "poisson": 0.3, "density": 1000},
      "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1]}]}],
    "render": {"width": 64, "height": 48, "every": 10}})";
  return file.string();
}

TEST(VideoCommand, RunWritesAnMp4AtTheSimulatedFrameRate) {
  const std::filesystem::path dir = test::test_out_dir() / "video_run";
  std::filesystem::remove_all(dir);
  const std::string scene = small_scene(dir);
  // No --render: --video renders mono. Steps 0, 10, 20, 30, 40: five frames.
  const int status = run(scene + " --quiet --out " + dir.string() + " --video " +
                         (dir / "block.mp4").string() + " 2> " + (dir / "err.txt").string());
  ASSERT_EQ(status, 0);
  const Decoded d = decode(dir / "block.mp4");
  EXPECT_EQ(d.frames, 5);
  EXPECT_EQ(d.width, 64);
  EXPECT_EQ(d.height, 48);
  EXPECT_NEAR(d.rate, 1000, 1e-6);
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_000040.png")) << "PNG frames stay";
}

// render.video in the scene file: the MP4 goes into the run's output folder; no render mode
// set, so the run renders mono.
TEST(VideoCommand, SceneRenderVideoIsWrittenIntoTheOutputFolder) {
  const std::filesystem::path dir = test::test_out_dir() / "video_scene_key";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::string text;
  {
    std::ifstream in(small_scene(dir));
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string key = R"("every": 10})";
  ASSERT_NE(text.find(key), std::string::npos);
  text.replace(text.find(key), key.size(), R"("every": 20, "video": "clip.mp4"})");
  std::ofstream(dir / "keyed.json") << text;
  ASSERT_EQ(run((dir / "keyed.json").string() + " --quiet --out " + (dir / "out").string() +
                " 2> " + (dir / "err.txt").string()),
            0);
  const Decoded d = decode(dir / "out" / "clip.mp4");
  EXPECT_EQ(d.frames, 3);  // steps 0, 20 and 40
  EXPECT_EQ(d.width, 64);
  EXPECT_NEAR(d.rate, 500, 1e-6);
}

TEST(VideoCommand, UnwritableVideoPathIsRefusedBeforeTheRun) {
  const std::filesystem::path dir = test::test_out_dir() / "video_refused";
  std::filesystem::remove_all(dir);
  const std::filesystem::path err = test::test_out_dir() / "video_refused.err";
  const std::string scene = small_scene(dir);
  const int status = run(scene + " --quiet --out " + dir.string() +
                         " --video /nonexistent-folder/x.mp4 2> " + err.string());
  EXPECT_NE(status, 0);
  std::ifstream in(err);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.find("phyxel run: --video: /nonexistent-folder/x.mp4: cannot write the video ("),
            0u)
      << line;
  EXPECT_NE(line.find("cannot write the video"), std::string::npos) << line;
  EXPECT_FALSE(std::filesystem::exists(dir / "summary.json")) << "the run started";
}

// The README's demo (scripts/dev.sh demo): scenes/demo.json with --video, its first 800 steps
// (frames at steps 0, 400 and 800 of 2.5e-4 s: 10 frames per simulated second at 960 x 540).
TEST(VideoCommand, TheReadmeDemoWritesItsVideoAndFrames) {
  const std::filesystem::path dir = test::test_out_dir() / "video_demo";
  std::filesystem::remove_all(dir);
  const int status = run(std::string(PHYXEL_SOURCE_DIR) + "/scenes/demo.json --steps 800 --quiet" +
                         " --out " + dir.string() + " --video " + (dir / "demo.mp4").string() +
                         " 2> " + (dir.string() + ".err"));
  ASSERT_EQ(status, 0);
  const Decoded d = decode(dir / "demo.mp4");
  EXPECT_EQ(d.frames, 3);
  EXPECT_EQ(d.width, 960);
  EXPECT_EQ(d.height, 540);
  EXPECT_NEAR(d.rate, 10, 1e-6);
  EXPECT_TRUE(std::filesystem::exists(dir / "frame_000800.png"));
}

// `phyxel bench --render` ends with the encoder's rate at the frames' size (the 1080p-per-eye
// per eye figure on the device machine; here tiny, on lavapipe): a row in its JSON.
TEST(VideoCommand, RenderBenchReportsTheEncodeRate) {
  const std::filesystem::path json = test::test_out_dir() / "bench_render_encode.json";
  const std::string cmd = std::string(PHYXEL_BINARY_DIR) +
                          "/app/phyxel bench --render --surfels 1000 --width 64 --height 48 "
                          "--frames 2 --no-solver --json " +
                          json.string() + " > " + json.string() + ".out 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(json);
  const nlohmann::json rows = nlohmann::json::parse(in);
  ASSERT_FALSE(rows.empty());
  const nlohmann::json& last = rows.back();
  ASSERT_TRUE(last.contains("video_encode_frames_per_s")) << last.dump();
  EXPECT_EQ(last["video_encode_width"].get<int>(), 128);  // stereo: both eyes side by side
  EXPECT_EQ(last["video_encode_frames"].get<int>(), 30);
  EXPECT_GT(last["video_encode_frames_per_s"].get<double>(), 0.0);
  EXPECT_GT(last["video_convert_ms"].get<double>(), 0.0);
}

}  // namespace
}  // namespace phyxel::render
