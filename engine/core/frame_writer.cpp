#include "engine/core/frame_writer.h"

#include <algorithm>
#include <cstdio>
#include <thread>

#include "engine/core/png.h"

namespace strata {

std::string frame_file_name(size_t frame, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof name, "frame-%05zu.%s", frame, extension);
  return name;
}

unsigned default_frame_threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// One thread: the caller's, no worker. An MP4's encoding stays in order on one worker.
unsigned workers(const FrameWriter::Settings& s) {
  if (s.threads <= 1) return 0;
  return s.format == FrameWriter::Format::mp4 ? 1 : s.threads;
}

}  // namespace

FrameWriter::FrameWriter(const std::filesystem::path& output, const Settings& settings)
    : output_(output), settings_(settings), pool_(workers(settings), 2 * workers(settings)) {
  if (settings.format == Format::mp4) {
    video_ =
        std::make_unique<VideoFile>(output.string(), settings.width, settings.height, settings.fps);
  }
}

void FrameWriter::write(std::vector<uint8_t> rgba) {
  const size_t frame = frames_++;
  if (video_) {
    pool_.submit([video = video_.get(), rgba = std::move(rgba)] { video->write(rgba); });
    return;
  }
  pool_.submit([path = (output_ / frame_file_name(frame, "png")).string(), w = settings_.width,
                h = settings_.height, rgba = std::move(rgba)] { write_png(path, w, h, rgba); });
}

void FrameWriter::finish() {
  pool_.finish();
  if (video_) video_->finish();
}

}  // namespace strata
