#include "engine/core/video_file.h"

#include "engine/core/atomic_file.h"
#include "engine/core/error.h"

#if STRATA_VIDEO
#include "engine/core/gif_palette.h"

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
  std::unique_ptr<GifPalette> palette;  // a GIF's, instead of the frame and scaler
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

  const AVCodec* open_encoder(VideoFormat video, double fps);
  void open_conversion(VideoFormat video);

  // The next frame of the video: `f` with its time.
  void encode_next(AVFrame* f) {
    f->pts = next_pts++;
    encode(f);
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

namespace {

const char* kind(VideoFormat format) {
  return format == VideoFormat::gif ? "GIF" : "MP4";
}

}  // namespace

// The encoder's settings for the format: H.264 in YUV 4:2:0 at a quality for sharp text, or GIF's
// palette frames.
const AVCodec* VideoFile::Codec::open_encoder(VideoFormat video, double fps) {
  const AVCodec* codec = nullptr;
  if (video == VideoFormat::gif) {
    codec = avcodec_find_encoder(AV_CODEC_ID_GIF);
    if (!codec) throw Error(path + ": this FFmpeg has no GIF encoder");
  } else {
    codec = avcodec_find_encoder_by_name("libx264");
    if (!codec) codec = avcodec_find_encoder(AV_CODEC_ID_H264);
    if (!codec) throw Error(path + ": this FFmpeg has no H.264 encoder");
  }
  stream = avformat_new_stream(format, nullptr);
  encoder = avcodec_alloc_context3(codec);
  if (!stream || !encoder) throw Error(path + ": out of memory");
  const AVRational rate = av_d2q(fps, 100000);
  encoder->width = int(width);
  encoder->height = int(height);
  encoder->time_base = av_inv_q(rate);
  encoder->framerate = rate;
  if (format->oformat->flags & AVFMT_GLOBALHEADER) {
    encoder->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  }
  if (video == VideoFormat::gif) {
    encoder->pix_fmt = AV_PIX_FMT_PAL8;
    return codec;
  }
  encoder->pix_fmt = AV_PIX_FMT_YUV420P;
  encoder->gop_size = int(2 * fps);
  encoder->thread_count = 0;  // the encoder's own threads, as many as it sees fit (libx264's)
  // Sharp text and thin leaders: a low constant rate factor (libx264's quality scale).
  av_opt_set(encoder->priv_data, "crf", "18", 0);
  av_opt_set(encoder->priv_data, "preset", "medium", 0);
  return codec;
}

// An MP4's frames are converted to YUV by one scaler into one frame; a GIF's through its palette.
void VideoFile::Codec::open_conversion(VideoFormat video) {
  if (video == VideoFormat::gif) {
    palette = std::make_unique<GifPalette>(path, width, height);
    return;
  }
  frame = av_frame_alloc();
  if (!frame) throw Error(path + ": out of memory");
  frame->format = encoder->pix_fmt;
  frame->width = encoder->width;
  frame->height = encoder->height;
  check(av_frame_get_buffer(frame, 0), "allocating a frame");
  scaler = sws_getContext(int(width), int(height), AV_PIX_FMT_RGBA, int(width), int(height),
                          AV_PIX_FMT_YUV420P, SWS_BICUBIC, nullptr, nullptr, nullptr);
  if (!scaler) throw Error(path + ": no RGBA to YUV conversion");
}

VideoFile::VideoFile(const std::string& path, uint32_t width, uint32_t height, double fps,
                     VideoFormat format)
    : codec_(std::make_unique<Codec>()) {
  Codec& c = *codec_;
  c.path = path;
  av_log_set_level(AV_LOG_ERROR);  // (the encoder's statistics are not for the user)
  c.width = width;
  c.height = height;
  if (format == VideoFormat::mp4 && (width % 2 || height % 2)) {
    throw Error(path + ": an H.264 video needs an even width and height, not " +
                std::to_string(width) + "x" + std::to_string(height));
  }
  c.check(avformat_alloc_output_context2(&c.format, nullptr,
                                         format == VideoFormat::gif ? "gif" : "mp4", nullptr),
          "creating the file");
  const AVCodec* codec = c.open_encoder(format, fps);
  c.packet = av_packet_alloc();
  if (!c.packet) throw Error(path + ": out of memory");
  c.check(avcodec_open2(c.encoder, codec, nullptr), "opening the encoder");
  c.check(avcodec_parameters_from_context(c.stream->codecpar, c.encoder), "setting the stream");
  c.stream->time_base = c.encoder->time_base;
  c.open_conversion(format);

  c.file = std::make_unique<AtomicFile>(path, kind(format));
  c.check(avio_open(&c.format->pb, c.file->temporary().c_str(), AVIO_FLAG_WRITE),
          "opening the file");
  // Every packet goes to the file as it comes, so a full disk stops the video at the first frame
  // that does not fit, not after every frame was rendered (FFmpeg would buffer them).
  c.format->flush_packets = 1;
  AVDictionary* options = nullptr;
  if (format == VideoFormat::gif) av_dict_set(&options, "loop", "0", 0);  // 0: forever
  const int written = avformat_write_header(c.format, &options);
  av_dict_free(&options);
  c.check(written, "writing the header");
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
  if (c.palette) {
    c.palette->add(rgba, [&c](AVFrame* mapped) { c.encode_next(mapped); });
    return;
  }
  c.check(av_frame_make_writable(c.frame), "preparing a frame");
  const uint8_t* rows[] = {rgba.data()};
  const int stride[] = {int(c.width * 4)};
  sws_scale(c.scaler, rows, stride, 0, int(c.height), c.frame->data, c.frame->linesize);
  c.encode_next(c.frame);
}

void VideoFile::finish() {
  Codec& c = *codec_;
  if (c.finished) return;
  c.finished = true;
  if (c.palette) c.palette->finish([&c](AVFrame* mapped) { c.encode_next(mapped); });
  c.encode(nullptr);
  c.check(av_write_trailer(c.format), "writing the index");
  c.check(avio_closep(&c.format->pb), "closing the file");
  c.file->commit();
}

}  // namespace strata

#else  // built with STRATA_VIDEO=OFF

namespace strata {

struct VideoFile::Codec {};

VideoFile::VideoFile(const std::string& path, uint32_t, uint32_t, double, VideoFormat) {
  throw Error(path +
              ": this strata was built without video output (STRATA_VIDEO=OFF); write PNG "
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
