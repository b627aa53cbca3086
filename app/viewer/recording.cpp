// What the viewer writes of its pictures: screenshots, captures with the panel, layouts and
// videos.
#include "app/viewer/viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "engine/core/png.h"
#include "engine/core/text_file.h"

namespace strata::app {

std::filesystem::path Viewer::screenshot(const std::filesystem::path& path) {
  std::filesystem::path out = path;
  if (out.empty()) {
    const std::string stem = scene_.source.empty() ? "strata" : scene_.source.stem().string();
    do {
      char name[64];
      std::snprintf(name, sizeof name, "-%03u.png", ++screenshots_);
      out = options_.screenshot_dir / (stem + name);
    } while (std::filesystem::exists(out));
  }
  std::vector<uint8_t> pixels = download(labelled_->labelled_image());
  if (annotations_) annotations_->draw(pixels, annotation_layout_);
  write_png(out.string(), labelled_->size().width, labelled_->size().height, pixels);
  message_ = "wrote " + out.string();
  std::printf("view: screenshot %s\n", out.string().c_str());
  std::fflush(stdout);
  ui_event();
  return out;
}

void Viewer::capture(const std::filesystem::path& path) {
  write_png(path.string(), labelled_->size().width, labelled_->size().height,
            download(display_id_));
}

// An rgba8 image of the last frame, once the frames in flight have finished.
std::vector<uint8_t> Viewer::download(graph::ResourceId image) {
  output_.wait_idle();
  const std::vector<std::byte> bytes = labelled_->runner().download_image(image);
  const auto* p = reinterpret_cast<const uint8_t*>(bytes.data());
  return {p, p + bytes.size()};
}

// After the frames in flight finished: the results of the last one.
void Viewer::read_latest() {
  output_.wait_idle();
  labelled_->use_slot(last_slot_);
}

void Viewer::write_layout(const std::filesystem::path& path) {
  read_latest();
  write_text_file(path, layout_json(labelled_->result()));
}

void Viewer::start_recording(const std::filesystem::path& path) {
  if (recording()) stop_recording();
  recorder_.start(path, labelled_->size(), options_.record_fps);
  message_ = "recording " + path.string();
}

void Viewer::stop_recording() {
  if (!recording()) return;
  output_.wait_idle();  // (the frames in flight are the video's last)
  const uint64_t frames = recorder_.finish();
  message_ = "wrote " + recorder_.path().string() + " (" + std::to_string(frames) + " frames)";
  std::printf("view: video %s, %llu frames\n", recorder_.path().string().c_str(),
              static_cast<unsigned long long>(frames));
  std::fflush(stdout);
}

}  // namespace strata::app
