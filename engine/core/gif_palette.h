// A GIF's frames mapped to one palette of 256 colours for the whole clip, by FFmpeg's palettegen
// and paletteuse (libavfilter). The palette is made from the frames seen, so the first frames are
// held in memory until the clip ends or they reach kGifHeldBytes; frames after that are mapped to
// the palette of those as they come. Used by VideoFile (video_file.h) only.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

struct AVFrame;

namespace strata {

// The frames held for the palette at most: 256 frames of 512 x 512, about 8 s at 30 fps.
inline constexpr size_t kGifHeldBytes = size_t{256} << 20;

class GifPalette {
 public:
  // Receives each frame mapped to the palette (PAL8, the palette in data[1]), in order.
  using FrameOut = std::function<void(AVFrame*)>;

  // Errors name `path`; `held_bytes`: the frames held for the palette at most.
  GifPalette(std::string path, uint32_t width, uint32_t height,
             size_t held_bytes = kGifHeldBytes);
  ~GifPalette();
  GifPalette(const GifPalette&) = delete;
  GifPalette& operator=(const GifPalette&) = delete;

  // One frame of width x height RGBA8, rows top to bottom; nothing comes out until the palette is
  // made (at finish(), or once the held frames reach held_bytes).
  void add(std::span<const uint8_t> rgba, const FrameOut& out);
  // Makes the palette if not yet made and maps every frame still held.
  void finish(const FrameOut& out);

 private:
  struct Filters;
  std::unique_ptr<Filters> filters_;
};

}  // namespace strata
