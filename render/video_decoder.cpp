#include "render/video_decoder.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libswscale/swscale.h>
}

namespace phyxel::render {
namespace {

std::string av_text(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

}  // namespace

struct VideoDecoder::Impl {
  std::string file;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  SwsContext* scale = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  int stream = -1;
  bool flushed = false;  // the end of the file was sent to the decoder
  bool pending = false;  // `frame` holds a decoded frame not yet handed out

  [[noreturn]] void fail(const std::string& what, int code = 0) const {
    throw std::runtime_error(file + ": cannot decode the video (" + what +
                             (code < 0 ? ": " + av_text(code) : std::string()) + ")");
  }
  // Decodes the next frame into `frame`; false at the end.
  bool decode() {
    if (pending) {
      pending = false;
      return true;
    }
    for (;;) {
      const int got = avcodec_receive_frame(codec, frame);
      if (got == 0) return true;
      if (got == AVERROR_EOF) return false;
      if (got != AVERROR(EAGAIN)) fail("decoding a frame", got);
      if (flushed) return false;
      const int read = av_read_frame(format, packet);
      if (read == AVERROR_EOF || (read < 0 && avio_feof(format->pb))) {
        flushed = true;
        avcodec_send_packet(codec, nullptr);
        continue;
      }
      if (read < 0) fail("reading the file", read);
      if (packet->stream_index == stream) {
        const int sent = avcodec_send_packet(codec, packet);
        av_packet_unref(packet);
        if (sent < 0 && sent != AVERROR(EAGAIN)) fail("decoding a packet", sent);
      } else {
        av_packet_unref(packet);
      }
    }
  }
  ~Impl() {
    if (scale != nullptr) sws_freeContext(scale);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format != nullptr) avformat_close_input(&format);
  }
};

VideoDecoder::VideoDecoder(const std::filesystem::path& file, uint32_t max_side)
    : impl_(std::make_unique<Impl>()), file_(file.string()) {
  Impl& m = *impl_;
  m.file = file_;
  av_log_set_level(AV_LOG_QUIET);  // our message says what failed; FFmpeg's would repeat it
  int code = avformat_open_input(&m.format, m.file.c_str(), nullptr, nullptr);
  if (code < 0) m.fail("not a video file FFmpeg reads", code);
  code = avformat_find_stream_info(m.format, nullptr);
  if (code < 0) m.fail("no stream information", code);
  const AVCodec* decoder = nullptr;
  m.stream = av_find_best_stream(m.format, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (m.stream < 0) m.fail("it has no video stream FFmpeg decodes", m.stream);
  const AVStream* stream = m.format->streams[m.stream];
  m.codec = avcodec_alloc_context3(decoder);
  m.packet = av_packet_alloc();
  m.frame = av_frame_alloc();
  if (m.codec == nullptr || m.packet == nullptr || m.frame == nullptr) m.fail("out of memory");
  code = avcodec_parameters_to_context(m.codec, stream->codecpar);
  if (code < 0) m.fail("codec parameters", code);
  code = avcodec_open2(m.codec, decoder, nullptr);
  if (code < 0) m.fail(std::string("opening the ") + decoder->name + " decoder", code);
  AVRational rate = stream->avg_frame_rate;
  if (rate.num <= 0 || rate.den <= 0) rate = stream->r_frame_rate;
  if (rate.num > 0 && rate.den > 0) fps_ = av_q2d(rate);
  if (!m.decode()) m.fail("no frame decodes");
  m.pending = true;
  const double w = m.frame->width, h = m.frame->height;
  if (w <= 0 || h <= 0) m.fail("an empty frame");
  const double shrink = std::min(1.0, double(std::max<uint32_t>(max_side, 1)) / std::max(w, h));
  width_ = static_cast<uint32_t>(std::max(1.0, std::round(w * shrink)));
  height_ = static_cast<uint32_t>(std::max(1.0, std::round(h * shrink)));
}

VideoDecoder::~VideoDecoder() = default;

bool VideoDecoder::next(RgbaImage* out) {
  Impl& m = *impl_;
  if (!m.decode()) return false;
  if (out == nullptr) return true;
  m.scale = sws_getCachedContext(
      m.scale, m.frame->width, m.frame->height, static_cast<AVPixelFormat>(m.frame->format),
      int(width_), int(height_), AV_PIX_FMT_RGBA,
      SWS_BICUBIC | SWS_ACCURATE_RND | SWS_FULL_CHR_H_INT, nullptr, nullptr, nullptr);
  if (m.scale == nullptr) m.fail("no conversion of its pixel format to RGBA");
  if (out->width != width_ || out->height != height_) *out = RgbaImage(width_, height_);
  uint8_t* dst[1] = {out->pixels.data()};
  const int stride[1] = {static_cast<int>(width_ * 4)};
  sws_scale(m.scale, m.frame->data, m.frame->linesize, 0, m.frame->height, dst, stride);
  return true;
}

void VideoDecoder::rewind() {
  Impl& m = *impl_;
  const AVStream* stream = m.format->streams[m.stream];
  const int64_t start = stream->start_time != AV_NOPTS_VALUE ? stream->start_time : 0;
  int code = av_seek_frame(m.format, m.stream, start, AVSEEK_FLAG_BACKWARD);
  if (code < 0) code = avformat_seek_file(m.format, -1, INT64_MIN, 0, 0, 0);
  if (code < 0) m.fail("seeking to the start", code);
  avcodec_flush_buffers(m.codec);
  m.flushed = false;
  m.pending = false;
}

}  // namespace phyxel::render
