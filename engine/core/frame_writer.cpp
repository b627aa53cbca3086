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

std::vector<std::filesystem::path> frame_files_in(const std::filesystem::path& folder,
                                                  const char* extension) {
  const std::string suffix = std::string(".") + extension;
  const auto is_frame = [&](const std::string& name) {
    if (!name.starts_with("frame-") || !name.ends_with(suffix)) return false;
    const std::string digits = name.substr(6, name.size() - 6 - suffix.size());
    // (%05zu: five digits, or more without a leading zero)
    const bool width = digits.size() == 5 || (digits.size() > 5 && digits[0] != '0');
    return width &&
           std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  std::vector<std::filesystem::path> found;
  std::error_code error;
  for (std::filesystem::directory_iterator it(folder, error), end; !error && it != end;
       it.increment(error)) {
    std::error_code kind;
    if (is_frame(it->path().filename().string()) && !it->is_directory(kind))
      found.push_back(it->path());
  }
  std::sort(found.begin(), found.end());
  return found;
}

unsigned default_frame_threads() {
  return std::max(1u, std::thread::hardware_concurrency());
}

namespace {

// One thread: the caller's, no worker. A video's encoding stays in order on one worker.
unsigned workers(const FrameWriter::Settings& s) {
  if (s.threads <= 1) return 0;
  return s.format == FrameWriter::Format::png_folder ? s.threads : 1;
}

}  // namespace

FrameWriter::FrameWriter(const std::filesystem::path& output, const Settings& settings)
    : output_(output), settings_(settings), pool_(workers(settings), 2 * workers(settings)) {
  if (settings.format != Format::png_folder) {
    video_ = std::make_unique<VideoFile>(
        output.string(), settings.width, settings.height, settings.fps,
        settings.format == Format::gif ? VideoFormat::gif : VideoFormat::mp4);
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
