#include "render/video_writer.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "render/yuv_convert.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace phyxel::render {
namespace {

std::string av_message(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

}  // namespace

struct VideoWriter::Impl {
  std::string file;
  uint32_t width = 0, height = 0;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  SwsContext* scale = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  bool header = false, done = false;

  [[noreturn]] void fail(const std::string& what, int code) const {
    throw std::runtime_error(file + ": cannot write the video (" + what +
                             (code < 0 ? ": " + av_message(code) : std::string()) + ")");
  }
  void check(int code, const char* what) const {
    if (code < 0) fail(what, code);
  }
  // Sends `f` (null: flush) and writes every packet the encoder has ready.
  void encode(const AVFrame* f) {
    check(avcodec_send_frame(codec, f), "encoding a frame");
    for (;;) {
      const int got = avcodec_receive_packet(codec, packet);
      if (got == AVERROR(EAGAIN) || got == AVERROR_EOF) return;
      check(got, "encoding a frame");
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      check(av_interleaved_write_frame(format, packet), "writing a frame");
    }
  }
  ~Impl() {
    if (scale != nullptr) sws_freeContext(scale);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }
};

VideoWriter::VideoWriter(const std::filesystem::path& file, uint32_t width, uint32_t height,
                         double fps, VideoEncoding encoding, const std::string& preset)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.file = file.string();
  av_log_set_level(AV_LOG_ERROR);  // not x264's banner on every run; failures still say why
  m.width = width;
  m.height = height;
  if (width == 0 || height == 0 || !(fps > 0)) m.fail("empty frames or no frame rate", 0);
  const bool ffv1 = encoding == VideoEncoding::Ffv1;
  const bool lossless = encoding != VideoEncoding::H264;
  m.check(
      avformat_alloc_output_context2(&m.format, nullptr, ffv1 ? nullptr : "mp4", m.file.c_str()),
      ffv1 ? "a muxer for the file's extension" : "MP4 muxer");
  const AVCodec* encoder =
      ffv1 ? avcodec_find_encoder(AV_CODEC_ID_FFV1) : avcodec_find_encoder_by_name("libx264");
  if (encoder == nullptr)
    m.fail(std::string("libavcodec has no ") + (ffv1 ? "FFV1" : "libx264") +
               " encoder; run scripts/install-deps.sh",
           0);
  m.stream = avformat_new_stream(m.format, nullptr);
  m.codec = avcodec_alloc_context3(encoder);
  m.frame = av_frame_alloc();
  m.packet = av_packet_alloc();
  if (m.stream == nullptr || m.codec == nullptr || m.frame == nullptr || m.packet == nullptr)
    m.fail("out of memory", 0);
  const AVRational rate = av_d2q(fps, 1 << 16);
  const uint32_t even = ffv1 ? 1 : 2;  // 4:2:0 needs even sides
  m.codec->width = static_cast<int>((width + even - 1) / even * even);
  m.codec->height = static_cast<int>((height + even - 1) / even * even);
  m.codec->pix_fmt = ffv1 ? AV_PIX_FMT_BGR0 : lossless ? AV_PIX_FMT_YUV444P : AV_PIX_FMT_YUV420P;
  m.codec->time_base = av_inv_q(rate);
  m.codec->framerate = rate;
  m.codec->gop_size = 30;
  if (!lossless) {  // what rgba_to_yuv420 writes, so that players convert it back alike
    m.codec->color_range = AVCOL_RANGE_MPEG;
    m.codec->colorspace = AVCOL_SPC_SMPTE170M;
    m.codec->color_primaries = AVCOL_PRI_SMPTE170M;
    m.codec->color_trc = AVCOL_TRC_SMPTE170M;
  }
  if ((m.format->oformat->flags & AVFMT_GLOBALHEADER) != 0)
    m.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  // Quality over size (crf 18 is visually lossless), fast enough to keep up with the frames.
  if (!ffv1) {
    if (av_opt_set(m.codec->priv_data, "preset", preset.c_str(), 0) < 0)
      m.fail("x264 has no preset " + preset, 0);
    av_opt_set(m.codec->priv_data, lossless ? "qp" : "crf", lossless ? "0" : "18", 0);
  }
  m.check(avcodec_open2(m.codec, encoder, nullptr),
          ffv1 ? "opening the FFV1 encoder" : "opening the H.264 encoder");
  m.check(avcodec_parameters_from_context(m.stream->codecpar, m.codec), "stream parameters");
  m.stream->time_base = m.codec->time_base;
  m.stream->avg_frame_rate = rate;
  m.check(avio_open(&m.format->pb, m.file.c_str(), AVIO_FLAG_WRITE), "opening the file");
  m.check(avformat_write_header(m.format, nullptr), "writing the header");
  m.header = true;
  m.frame->format = m.codec->pix_fmt;
  m.frame->width = m.codec->width;
  m.frame->height = m.codec->height;
  m.check(av_frame_get_buffer(m.frame, 0), "frame buffer");
  if (!lossless) return;  // 4:2:0 frames are converted by rgba_to_yuv420 on several threads
  m.scale = sws_getContext(static_cast<int>(width), static_cast<int>(height), AV_PIX_FMT_RGBA,
                           m.codec->width, m.codec->height, m.codec->pix_fmt,
                           SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr,
                           nullptr);
  if (m.scale == nullptr) m.fail("no conversion from RGBA", 0);
}

VideoWriter::~VideoWriter() {
  try {
    finish();
  } catch (const std::exception&) {  // NOLINT(bugprone-empty-catch): a destructor stays quiet
  }
}

void VideoWriter::add(const RgbaImage& image, int64_t index) {
  Impl& m = *impl_;
  if (m.done) m.fail("a frame after finish()", 0);
  if (image.width != m.width || image.height != m.height) m.fail("a frame of another size", 0);
  m.check(av_frame_make_writable(m.frame), "frame buffer");
  if (m.scale == nullptr) {
    rgba_to_yuv420(image, {{m.frame->data[0], m.frame->data[1], m.frame->data[2]},
                           {m.frame->linesize[0], m.frame->linesize[1], m.frame->linesize[2]},
                           static_cast<uint32_t>(m.codec->width),
                           static_cast<uint32_t>(m.codec->height)});
  } else {
    const uint8_t* src[1] = {image.pixels.data()};
    const int stride[1] = {static_cast<int>(image.width * 4)};
    sws_scale(m.scale, src, stride, 0, static_cast<int>(image.height), m.frame->data,
              m.frame->linesize);
  }
  m.frame->pts = index;
  m.encode(m.frame);
  ++frames_;
}

void VideoWriter::finish() {
  Impl& m = *impl_;
  if (m.done || !m.header) return;
  m.done = true;
  m.encode(nullptr);
  m.check(av_write_trailer(m.format), "writing the MP4 index");
}

FrameSink::FrameSink(std::filesystem::path out_dir, bool png, std::unique_ptr<VideoWriter> video,
                     size_t max_queued, unsigned encoders)
    : out_dir_(std::move(out_dir)),
      png_(png),
      video_(std::move(video)),
      max_queued_(std::max<size_t>(max_queued, 1)),
      thread_([this] { run(); }) {
  if (!png_) return;
  if (encoders == 0) {
    const unsigned cores = std::max(std::thread::hardware_concurrency(), 1u);
    encoders = std::clamp(cores - 1, 1u, kMaxPngEncoders);
  }
  for (unsigned k = 0; k < encoders; ++k) png_threads_.emplace_back([this] { run_png(); });
}

FrameSink::~FrameSink() {
  try {
    finish();
  } catch (const std::exception&) {  // NOLINT(bugprone-empty-catch): a destructor stays quiet
  }
}

void FrameSink::rethrow() {
  if (error_) {
    std::exception_ptr e = std::exchange(error_, nullptr);
    std::rethrow_exception(e);
  }
}

void FrameSink::push(std::string name, RgbaImage image, int64_t video_index) {
  enqueue({std::move(name), std::move(image), video_index, {}});
}

void FrameSink::push(std::string name, std::function<RgbaImage()> produce, int64_t video_index) {
  enqueue({std::move(name), RgbaImage{}, video_index, std::move(produce)});
}

void FrameSink::enqueue(Job job) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return queue_.size() < max_queued_ || error_; });
  rethrow();
  if (finished_) throw std::logic_error("FrameSink::push after finish");
  queue_.push_back(std::move(job));
  changed_.notify_all();
}

bool FrameSink::idle() const {
  return queue_.empty() && !busy_ && png_queue_.empty() && png_busy_ == 0;
}

void FrameSink::fail(std::exception_ptr error) {
  if (!error_) error_ = std::move(error);
  queue_.clear();  // their read-back slots (FrameQueue) are released as the jobs go
  png_queue_.clear();
  changed_.notify_all();
}

void FrameSink::flush() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [this] { return idle() || error_; });
  rethrow();
}

void FrameSink::finish() {
  {
    std::unique_lock lock(mutex_);
    if (!finished_) {
      changed_.wait(lock, [this] { return idle() || error_; });
      finished_ = stop_ = true;
      changed_.notify_all();
    }
  }
  if (thread_.joinable()) thread_.join();
  for (std::thread& t : png_threads_)
    if (t.joinable()) t.join();
  std::lock_guard lock(mutex_);
  rethrow();
  if (video_) {
    std::unique_ptr<VideoWriter> video = std::move(video_);
    video->finish();
  }
}

void FrameSink::run() {
  int64_t last_index = -1;
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return !queue_.empty() || stop_; });
      if (queue_.empty()) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    try {
      if (job.produce) {
        job.image = job.produce();
        job.produce = nullptr;  // releases what it held (a read-back slot)
      }
      auto image = std::make_shared<const RgbaImage>(std::move(job.image));
      if (png_) {  // to the encoders (they write the files in any order)
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [this] { return png_queue_.size() < max_queued_ || error_; });
        if (!error_) {
          png_queue_.push_back({out_dir_ / job.name, image});
          changed_.notify_all();
        }
      }
      if (video_) {                                              // in order, on this thread
        last_index = std::max(job.video_index, last_index + 1);  // strictly increasing
        video_->add(*image, last_index);
      }
    } catch (...) {
      std::lock_guard lock(mutex_);
      fail(std::current_exception());
    }
    std::lock_guard lock(mutex_);
    busy_ = false;
    changed_.notify_all();
  }
}

void FrameSink::run_png() {
  for (;;) {
    PngJob job;
    {
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [this] { return !png_queue_.empty() || stop_; });
      if (png_queue_.empty()) return;
      job = std::move(png_queue_.front());
      png_queue_.pop_front();
      ++png_busy_;
    }
    try {
      write_png(job.file, *job.image);
    } catch (...) {
      std::lock_guard lock(mutex_);
      fail(std::current_exception());
    }
    std::lock_guard lock(mutex_);
    --png_busy_;
    changed_.notify_all();
  }
}

}  // namespace phyxel::render
