// A sequence of frames written as numbered PNGs in a folder, as an H.264 MP4 or as a GIF,
// compressed on worker threads (an OrderedPool) while the caller renders the next frame. The files
// are the same whatever the thread count: each PNG is one frame's alone, and a video's frames go
// to the encoder in order, on one thread (libx264 has threads of its own).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "engine/core/ordered_pool.h"
#include "engine/core/video_file.h"

namespace strata {

// "frame-00012.png": frame 12's file in a folder of frames (layouts use the same names).
std::string frame_file_name(size_t frame, const char* extension);
// The files in `folder` named as frame_file_name names them, sorted: an earlier run's frames.
// Nothing for a folder that does not exist.
std::vector<std::filesystem::path> frame_files_in(const std::filesystem::path& folder,
                                                  const char* extension);

// The thread count of a writer when none is asked for: one per hardware thread, at least one.
unsigned default_frame_threads();

class FrameWriter {
 public:
  enum class Format { png_folder, mp4, gif };
  struct Settings {
    Format format = Format::png_folder;
    uint32_t width = 0, height = 0;
    double fps = 30.0;  // (a video's)
    // 1: every frame compressed and written by write() itself, one after another; more: PNGs on
    // that many threads, a video on one.
    unsigned threads = 1;
  };

  // Opens the video (a temporary until finish(): VideoFile), or writes into an existing folder.
  FrameWriter(const std::filesystem::path& output, const Settings& settings);

  // Hands a frame of width x height RGBA8 pixels over; it is frame number frames(). Waits while
  // twice as many frames as there are workers are being written, and throws the error of an
  // earlier frame (the first by frame order, naming its file: "<file>: cannot write PNG: ...").
  void write(std::vector<uint8_t> rgba);
  // Waits for every frame and puts a video in place; throws the first frame's error as write().
  void finish();

  size_t frames() const { return frames_; }

 private:
  std::filesystem::path output_;
  Settings settings_;
  size_t frames_ = 0;
  std::unique_ptr<VideoFile> video_;  // (before pool_: destroyed once no job uses it)
  OrderedPool pool_;
};

}  // namespace strata
