// Video frames as RGBA images (libavformat for the container, libavcodec for the codec,
// libswscale to RGBA; Debian's FFmpeg libraries): any file FFmpeg plays. For the video texture
// (render/video_texture.h). Frames come in decoding order, evenly spaced at the stream's frame
// rate (presentation time stamps are not followed: a variable-rate video plays at its mean
// rate).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "render/image.h"

namespace phyxel::render {

class VideoDecoder {
 public:
  // Opens `file`'s best video stream and decodes its first frame. Frames are scaled down
  // (aspect kept) so that neither side exceeds `max_side`. Throws std::runtime_error
  // "FILE: cannot decode the video (REASON)" when the file is missing, is no video FFmpeg
  // reads, or its first frame does not decode.
  explicit VideoDecoder(const std::filesystem::path& file, uint32_t max_side = 1024);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;

  uint32_t width() const { return width_; }  // of the frames handed out
  uint32_t height() const { return height_; }
  double fps() const { return fps_; }  // the stream's average frame rate (25 if it has none)
  const std::string& file() const { return file_; }

  // The next frame into `frame` (null: decoded but not converted, to skip frames cheaply).
  // Returns false at the end of the stream. Throws std::runtime_error on a decoding error.
  bool next(RgbaImage* frame);
  // Back to the first frame.
  void rewind();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string file_;
  uint32_t width_ = 0, height_ = 0;
  double fps_ = 25;
};

}  // namespace phyxel::render
