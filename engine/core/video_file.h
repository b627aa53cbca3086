// Videos through FFmpeg's libraries (libavcodec, libavformat, libavfilter, libswscale from
// Debian): frames of opaque RGBA8 in, and out either H.264 in an MP4 file (libx264 when the build
// has it, else FFmpeg's default H.264 encoder) or an animated GIF that loops forever, its frames
// mapped to one palette for the clip (gif_palette.h).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace strata {

enum class VideoFormat { mp4, gif };

class VideoFile {
 public:
  // Opens `path` for writing; an MP4's width and height must be even (the stream is YUV 4:2:0).
  // A GIF shows each frame for 1 / fps seconds, rounded to its hundredths of a second.
  VideoFile(const std::string& path, uint32_t width, uint32_t height, double fps,
            VideoFormat format = VideoFormat::mp4);
  ~VideoFile();
  VideoFile(const VideoFile&) = delete;
  VideoFile& operator=(const VideoFile&) = delete;

  // Whether this build writes videos (STRATA_VIDEO): without, the constructor throws an Error
  // that says so.
  static bool built();

  // Appends one frame of width x height RGBA8 pixels, rows top to bottom (a GIF's first frames
  // are held until its palette is made: GifPalette).
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
