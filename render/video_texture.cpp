#include "render/video_texture.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "render/video_loop.h"
#include "render/vk_images.h"

namespace phyxel::render {
namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

VideoTexture::VideoTexture(const std::filesystem::path& file, const VideoTextureOptions& options)
    : options_(options), decoder_(file, options.max_side) {
  width_ = decoder_.width();
  height_ = decoder_.height();
  fps_ = decoder_.fps();
  while (decoder_.next(nullptr)) ++frames_;  // every frame decodes, and how many there are
  blend_ = loop_blend_frames(frames_, options.loop_blend);
  loop_ = frames_ - blend_;
  decoder_.rewind();
  decoder_at_ = 0;
  if (blend_ > 0) {
    for (int k = 0; k < loop_; ++k) decoder_.next(nullptr);
    for (int k = 0; k < blend_; ++k) {
      RgbaImage frame;
      if (!decoder_.next(&frame)) {
        throw std::runtime_error(decoder_.file() +
                                 ": cannot decode the video (fewer frames the second time)");
      }
      if (options_.repair_specular) repair_specular(frame, options_.specular);
      tail_.push_back(std::move(frame));
    }
    decoder_.rewind();
  }
  thread_ = std::thread([this] { run(); });
}

VideoTexture::~VideoTexture() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

int64_t VideoTexture::frame_index(double t) const {
  if (!(t > 0)) return 0;
  return static_cast<int64_t>(std::floor(t * fps_ + 1e-6));  // a frame's own time is its frame
}

RgbaImage VideoTexture::decode_content(int content) {
  if (content < decoder_at_) {
    decoder_.rewind();
    decoder_at_ = 0;
  }
  for (; decoder_at_ < content; ++decoder_at_) decoder_.next(nullptr);
  RgbaImage frame;
  if (!decoder_.next(&frame)) {
    throw std::runtime_error(decoder_.file() + ": cannot decode the video (frame " +
                             std::to_string(content) + " is missing the second time)");
  }
  ++decoder_at_;
  return frame;
}

void VideoTexture::run() {
  for (;;) {
    int64_t index = 0;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock,
                    [&] { return stop_ || restart_ >= 0 || queue_.size() < options_.queued; });
      if (stop_) return;
      if (restart_ >= 0) {
        produce_ = restart_;
        restart_ = -1;
      }
      index = produce_;
    }
    try {
      const auto start = std::chrono::steady_clock::now();
      const int content = static_cast<int>(index % loop_);
      RgbaImage frame = decode_content(content);
      const double decode_s = seconds_since(start);
      const auto process = std::chrono::steady_clock::now();
      if (options_.repair_specular) repair_specular(frame, options_.specular);
      if (content < blend_) blend_loop_frame(frame, tail_[size_t(content)], content, blend_);
      std::vector<RgbaImage> levels = mip_chain(frame, options_.max_side);
      const double process_s = seconds_since(process);
      std::lock_guard lock(mutex_);
      timing_.decode_s += decode_s;
      timing_.process_s += process_s;
      ++timing_.frames;
      if (restart_ >= 0 || index != produce_) continue;  // asked for another frame meanwhile
      queue_.push_back({index, std::move(levels)});
      ++produce_;
    } catch (...) {
      std::lock_guard lock(mutex_);
      error_ = std::current_exception();
      changed_.notify_all();
      return;
    }
    changed_.notify_all();
  }
}

void VideoTexture::restart(int64_t index) {
  queue_.clear();
  restart_ = index;
  changed_.notify_all();
}

void VideoTexture::rethrow() {
  if (error_) std::rethrow_exception(error_);
}

const std::vector<RgbaImage>* VideoTexture::frame_at(double t) {
  const int64_t k = frame_index(t);
  if (k == current_index_) return nullptr;
  std::unique_lock lock(mutex_);
  rethrow();
  const int64_t first = restart_ >= 0 ? restart_ : queue_.empty() ? produce_ : queue_.front().index;
  // Back in time, or further ahead than a loop: start there instead of decoding up to it.
  if (k < first || k >= first + loop_ + int64_t(options_.queued)) restart(k);
  for (;;) {
    while (!queue_.empty() && queue_.front().index < k) queue_.pop_front();
    if (!queue_.empty() && queue_.front().index == k) break;
    changed_.notify_all();  // room in the queue
    changed_.wait(lock, [&] { return error_ || !queue_.empty(); });
    rethrow();
  }
  current_ = std::move(queue_.front().levels);
  current_index_ = k;
  queue_.pop_front();
  changed_.notify_all();
  return &current_;
}

const std::vector<RgbaImage>* VideoTexture::newest(double t) {
  const int64_t k = frame_index(t);
  std::lock_guard lock(mutex_);
  rethrow();
  if (k < current_index_ && restart_ < 0 &&
      (queue_.empty() || queue_.front().index > k)) {  // time went back (a reset)
    restart(k);
    return nullptr;
  }
  bool found = false;
  while (!queue_.empty() && queue_.front().index <= k) {
    current_ = std::move(queue_.front().levels);
    current_index_ = queue_.front().index;
    queue_.pop_front();
    found = true;
  }
  changed_.notify_all();
  return found ? &current_ : nullptr;
}

VideoTexture::Timing VideoTexture::timing() const {
  std::lock_guard lock(mutex_);
  return timing_;
}

}  // namespace phyxel::render
