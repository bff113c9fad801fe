// H.264 in MP4 of the rendered frames (libavformat, libavcodec with Debian's libx264;
// RGBA -> YUV 4:2:0 by render/yuv_convert.h on several threads, libswscale for the lossless
// encodings), for `phyxel run --video` and render.video, and the writer thread that takes PNG
// and video writing off the simulation thread.
//
//   VideoWriter  one MP4 file: frames of one size at a constant rate (the scene's simulated
//                time between frames, render.every x simulation.dt); an odd side gets its
//                last column or row repeated (4:2:0 needs even sides)
//   FrameSink    a thread that writes frames handed to it (PNG files and/or the video), a few
//                frames queued at most; failures come back from the next push() or finish()
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "render/image.h"

namespace phyxel::render {

enum class VideoEncoding {
  H264,          // MP4, CRF 18 in YUV 4:2:0 (what players expect of rendered frames)
  H264Lossless,  // MP4, QP 0 in YUV 4:4:4 (High 4:4:4 Predictive; only the RGB <-> YUV
                 // rounding is lost: the clips of tools/make_video_clip)
  Ffv1,          // FFV1 in RGB, exactly lossless, the container from the file's extension
                 // (.mkv, .avi, .nut): a second container and codec for the video texture's tests
};

// x264's preset of --video: "veryfast" keeps CRF 18 visually lossless at a rate that stereo
// 1080p needs (docs/performance.md).
inline constexpr const char* kVideoPreset = "veryfast";

class VideoWriter {
 public:
  // Opens `file` (created or truncated) for frames of width x height at `fps` frames per
  // second of the video. Throws std::runtime_error "FILE: cannot write the video (REASON)"
  // when the file cannot be opened or the encoder is missing. `encoding`: see VideoEncoding.
  // `preset`: x264's speed preset for the H.264 encodings (bench --render --video-preset).
  VideoWriter(const std::filesystem::path& file, uint32_t width, uint32_t height, double fps,
              VideoEncoding encoding = VideoEncoding::H264,
              const std::string& preset = kVideoPreset);
  ~VideoWriter();  // finishes the file when finish() was not called (errors then ignored)
  VideoWriter(const VideoWriter&) = delete;
  VideoWriter& operator=(const VideoWriter&) = delete;

  // Encodes one frame (of the size given at construction) at frame number `index` of the
  // video (strictly increasing; gaps hold the previous frame). Throws std::runtime_error.
  void add(const RgbaImage& frame, int64_t index);
  // Flushes the encoder and writes the MP4 index. Idempotent.
  void finish();
  int64_t frames() const { return frames_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int64_t frames_ = 0;
};

class FrameSink {
 public:
  static constexpr unsigned kMaxPngEncoders = 8;
  // Writes into `out_dir` the frames pushed with a name (PNG when `png`), and adds each to
  // `video` when given, on a thread of its own; the PNG files are encoded by `encoders` more
  // threads (0: one fewer than the cores, at most kMaxPngEncoders): a stereo 2 x 1280 x 720
  // frame takes one of them about 50-85 ms, so 60 frames a second take five or more.
  FrameSink(std::filesystem::path out_dir, bool png, std::unique_ptr<VideoWriter> video,
            size_t max_queued = 4, unsigned encoders = 0);
  ~FrameSink();  // finish(), errors ignored
  FrameSink(const FrameSink&) = delete;
  FrameSink& operator=(const FrameSink&) = delete;

  // Queues a frame (waits while max_queued are queued). `video_index`: its frame number in
  // the video. Rethrows a failure of an earlier frame.
  void push(std::string name, RgbaImage image, int64_t video_index);
  // The same for a frame whose pixels `produce` gives on the sink's thread (a read-back
  // buffer's copy, render/frame_queue.h). `produce` is destroyed once it ran, or unrun when the
  // frame is dropped after a failure: what it holds is released either way.
  void push(std::string name, std::function<RgbaImage()> produce, int64_t video_index);
  // Waits until every frame queued so far is written; rethrows a failure.
  void flush();
  // flush(), then finishes the video; no push() after it.
  void finish();

 private:
  struct Job {
    std::string name;
    RgbaImage image;
    int64_t video_index;
    std::function<RgbaImage()> produce;  // when set, gives `image` on the sink's thread
  };
  struct PngJob {
    std::filesystem::path file;
    std::shared_ptr<const RgbaImage> image;
  };
  void enqueue(Job job);
  void run();
  void run_png();
  void fail(std::exception_ptr error);  // with mutex_ held: keeps the first, drops the queues
  bool idle() const;                    // with mutex_ held: nothing queued or in hand
  void rethrow();

  std::filesystem::path out_dir_;
  bool png_;
  std::unique_ptr<VideoWriter> video_;
  size_t max_queued_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> queue_;
  std::deque<PngJob> png_queue_;
  size_t png_busy_ = 0;  // PNG files being encoded
  bool busy_ = false, stop_ = false, finished_ = false;
  std::exception_ptr error_;
  std::vector<std::thread> png_threads_;
  std::thread thread_;
};

}  // namespace phyxel::render
