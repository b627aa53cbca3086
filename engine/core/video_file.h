// H.264 video in an MP4 file through FFmpeg's libraries (libavcodec, libavformat, libswscale from
// Debian): frames of straight RGBA8 in, one H.264 stream out. The encoder is libx264 when the
// build has it, else FFmpeg's default H.264 encoder.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace strata {

class VideoFile {
 public:
  // Opens `path` for writing; width and height must be even (the stream is YUV 4:2:0).
  VideoFile(const std::string& path, uint32_t width, uint32_t height, double fps);
  ~VideoFile();
  VideoFile(const VideoFile&) = delete;
  VideoFile& operator=(const VideoFile&) = delete;

  // Whether this build writes MP4 (STRATA_VIDEO): without, the constructor throws an Error that
  // says so.
  static bool built();

  // Appends one frame of width x height RGBA8 pixels, rows top to bottom.
  void write(std::span<const uint8_t> rgba);
  // Flushes the encoder, writes the file's index and puts the file in place. Until then the frames
  // go to a temporary file (atomic_file.h): a video destroyed unfinished (an error on the way)
  // leaves nothing at `path`.
  void finish();

 private:
  struct Codec;
  std::unique_ptr<Codec> codec_;
};

}  // namespace strata
