#include "engine/core/video_file.h"

#include "engine/core/atomic_file.h"
#include "engine/core/error.h"

#if STRATA_VIDEO
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

namespace strata {

struct VideoFile::Codec {
  std::string path;
  uint32_t width = 0, height = 0;
  AVFormatContext* format = nullptr;
  AVCodecContext* encoder = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* scaler = nullptr;
  int64_t next_pts = 0;
  bool finished = false;
  // FFmpeg writes the temporary; finish() renames it into place, anything else removes it.
  // (Declared last: destroyed after ~Codec has closed FFmpeg's handle on it.)
  std::unique_ptr<AtomicFile> file;

  // Throws Error("<path>: <what>: <FFmpeg's reason>") when an FFmpeg call failed.
  void check(int result, const char* what) const {
    if (result >= 0) return;
    char reason[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(result, reason, sizeof reason);
    throw Error(path + ": " + what + ": " + reason);
  }

  // Sends `f` (null: the end) to the encoder and writes every packet it has ready.
  void encode(AVFrame* f) {
    check(avcodec_send_frame(encoder, f), "encoding a frame");
    for (;;) {
      const int result = avcodec_receive_packet(encoder, packet);
      if (result == AVERROR(EAGAIN) || result == AVERROR_EOF) return;
      check(result, "encoding a frame");
      // Every frame lasts one frame: without a duration the MP4's edit list cuts the last frame.
      if (packet->duration == 0) packet->duration = 1;
      av_packet_rescale_ts(packet, encoder->time_base, stream->time_base);
      packet->stream_index = stream->index;
      check(av_interleaved_write_frame(format, packet), "writing a frame");
    }
  }

  ~Codec() {
    sws_freeContext(scaler);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&encoder);
    if (format && format->pb) avio_closep(&format->pb);
    avformat_free_context(format);
  }
};

VideoFile::VideoFile(const std::string& path, uint32_t width, uint32_t height, double fps)
    : codec_(std::make_unique<Codec>()) {
  Codec& c = *codec_;
  c.path = path;
  av_log_set_level(AV_LOG_ERROR);  // (the encoder's statistics are not for the user)
  c.width = width;
  c.height = height;
  if (width % 2 || height % 2) {
    throw Error(path + ": an H.264 video needs an even width and height, not " +
                std::to_string(width) + "x" + std::to_string(height));
  }
  c.check(avformat_alloc_output_context2(&c.format, nullptr, "mp4", nullptr),
          "creating an MP4 file");
  const AVCodec* h264 = avcodec_find_encoder_by_name("libx264");
  if (!h264) h264 = avcodec_find_encoder(AV_CODEC_ID_H264);
  if (!h264) throw Error(path + ": this FFmpeg has no H.264 encoder");
  c.stream = avformat_new_stream(c.format, nullptr);
  c.encoder = avcodec_alloc_context3(h264);
  c.frame = av_frame_alloc();
  c.packet = av_packet_alloc();
  if (!c.stream || !c.encoder || !c.frame || !c.packet) throw Error(path + ": out of memory");

  const AVRational rate = av_d2q(fps, 100000);
  c.encoder->width = int(width);
  c.encoder->height = int(height);
  c.encoder->time_base = av_inv_q(rate);
  c.encoder->framerate = rate;
  c.encoder->pix_fmt = AV_PIX_FMT_YUV420P;
  c.encoder->gop_size = int(2 * fps);
  c.encoder->thread_count = 0;  // the encoder's own threads, as many as it sees fit (libx264's)
  if (c.format->oformat->flags & AVFMT_GLOBALHEADER) {
    c.encoder->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  }
  // Sharp text and thin leaders: a low constant rate factor (libx264's quality scale).
  av_opt_set(c.encoder->priv_data, "crf", "18", 0);
  av_opt_set(c.encoder->priv_data, "preset", "medium", 0);
  c.check(avcodec_open2(c.encoder, h264, nullptr), "opening the H.264 encoder");
  c.check(avcodec_parameters_from_context(c.stream->codecpar, c.encoder), "setting the stream");
  c.stream->time_base = c.encoder->time_base;

  c.frame->format = c.encoder->pix_fmt;
  c.frame->width = c.encoder->width;
  c.frame->height = c.encoder->height;
  c.check(av_frame_get_buffer(c.frame, 0), "allocating a frame");
  c.scaler = sws_getContext(int(width), int(height), AV_PIX_FMT_RGBA, int(width), int(height),
                            AV_PIX_FMT_YUV420P, SWS_BICUBIC, nullptr, nullptr, nullptr);
  if (!c.scaler) throw Error(path + ": no RGBA to YUV conversion");
  c.file = std::make_unique<AtomicFile>(path, "MP4");
  c.check(avio_open(&c.format->pb, c.file->temporary().c_str(), AVIO_FLAG_WRITE),
          "opening the file");
  // Every packet goes to the file as it comes, so a full disk stops the video at the first frame
  // that does not fit, not after every frame was rendered (FFmpeg would buffer them).
  c.format->flush_packets = 1;
  c.check(avformat_write_header(c.format, nullptr), "writing the header");
  avio_flush(c.format->pb);
  c.check(c.format->pb->error, "writing the header");
}

VideoFile::~VideoFile() = default;

bool VideoFile::built() {
  return true;
}

void VideoFile::write(std::span<const uint8_t> rgba) {
  Codec& c = *codec_;
  if (rgba.size() != size_t{c.width} * c.height * 4) {
    throw Error(c.path + ": a frame of " + std::to_string(rgba.size()) + " bytes for " +
                std::to_string(c.width) + "x" + std::to_string(c.height) + " RGBA");
  }
  c.check(av_frame_make_writable(c.frame), "preparing a frame");
  const uint8_t* rows[] = {rgba.data()};
  const int stride[] = {int(c.width * 4)};
  sws_scale(c.scaler, rows, stride, 0, int(c.height), c.frame->data, c.frame->linesize);
  c.frame->pts = c.next_pts++;
  c.encode(c.frame);
}

void VideoFile::finish() {
  Codec& c = *codec_;
  if (c.finished) return;
  c.finished = true;
  c.encode(nullptr);
  c.check(av_write_trailer(c.format), "writing the index");
  c.check(avio_closep(&c.format->pb), "closing the file");
  c.file->commit();
}

}  // namespace strata

#else  // built with STRATA_VIDEO=OFF

namespace strata {

struct VideoFile::Codec {};

VideoFile::VideoFile(const std::string& path, uint32_t, uint32_t, double) {
  throw Error(path +
              ": this strata was built without MP4 output (STRATA_VIDEO=OFF); write PNG "
              "frames to a folder instead");
}
VideoFile::~VideoFile() = default;
bool VideoFile::built() {
  return false;
}
void VideoFile::write(std::span<const uint8_t>) {}
void VideoFile::finish() {}

}  // namespace strata

#endif
