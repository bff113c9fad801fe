// A video as the objects' texture (`render.video_texture`, the paper's section VI): frames
// decoded (render/video_decoder.h), their specular spots repaired (render/specular_repair.h)
// and the loop's first frames blended with its last (render/video_loop.h, eq 32), each with
// its mip chain built, ahead of use on a thread of its own with a few frames queued, so that
// decoding never stalls a frame. The clip loops; frame index = floor(t x fps) of simulated
// time t, over L = N - loop_blend frames per loop.
//
//   frame_at(t)   the frame of simulated time t exactly, waiting for the thread when it is not
//                 ready yet (`phyxel run`: frames are deterministic)
//   newest(t)     the newest frame ready whose time is not after t, never waiting (the viewer)
//
// Both return null when the frame is the one handed out last (nothing to upload), else the
// mip chain (vk_images.h) for SplatRenderer::set_texture, valid until the next call.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include "render/image.h"
#include "render/specular_repair.h"
#include "render/video_decoder.h"

namespace phyxel::render {

struct VideoTextureOptions {
  int loop_blend = 0;            // B (eq 32); at most half the clip
  bool repair_specular = false;  // eq 31 segmentation, 1.1x magnified spot, repair
  SpecularOptions specular;
  uint32_t max_side = 1024;  // frames larger than this are scaled down when decoded
  size_t queued = 4;         // frames decoded ahead at most
};

class VideoTexture {
 public:
  // Opens and reads the whole clip once (its frame count, and the last B frames for the loop
  // blend), then starts the thread. Throws std::runtime_error "FILE: cannot decode the video
  // (REASON)" for a file that is missing or does not decode.
  explicit VideoTexture(const std::filesystem::path& file, const VideoTextureOptions& options = {});
  ~VideoTexture();
  VideoTexture(const VideoTexture&) = delete;
  VideoTexture& operator=(const VideoTexture&) = delete;

  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  double fps() const { return fps_; }
  int frames() const { return frames_; }     // N, in the file
  int loop_frames() const { return loop_; }  // L = N - B
  int64_t frame_index(double t) const;       // floor(t x fps), 0 for t < 0

  // See above. Rethrow a failure of the thread (a frame that no longer decodes).
  const std::vector<RgbaImage>* frame_at(double t);
  const std::vector<RgbaImage>* newest(double t);
  int64_t current_index() const { return current_index_; }  // last handed out, -1 before

  struct Timing {
    double decode_s = 0;   // decoding and conversion to RGBA
    double process_s = 0;  // specular repair, loop blend and mip chain
    int64_t frames = 0;    // frames made by the thread
  };
  Timing timing() const;

 private:
  struct Slot {
    int64_t index;
    std::vector<RgbaImage> levels;
  };
  void run();
  RgbaImage decode_content(int content);  // frame `content` (0 ... L-1) of the loop
  void restart(int64_t index);            // with mutex_ held
  void rethrow();                         // with mutex_ held

  VideoTextureOptions options_;
  VideoDecoder decoder_;
  uint32_t width_ = 0, height_ = 0;
  double fps_ = 25;
  int frames_ = 0, blend_ = 0, loop_ = 0;
  std::vector<RgbaImage> tail_;  // frames L ... N-1, repaired
  int decoder_at_ = 0;           // the content index that decoder_.next gives next

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Slot> queue_;
  int64_t produce_ = 0;   // the index the thread makes next
  int64_t restart_ = -1;  // >= 0: the thread starts again at this index
  bool stop_ = false;
  std::exception_ptr error_;
  Timing timing_;
  std::vector<RgbaImage> current_;
  int64_t current_index_ = -1;
  std::thread thread_;
};

}  // namespace phyxel::render
