// `strata bench encode`: how fast `strata video` compresses its frames, without a GPU: frames of
// a made-up picture through the same FrameWriter, to PNG (worker threads), to an H.264 MP4 and to
// a GIF, frames a second for each as JSON. The same command on two machines compares their CPUs
// alone.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <thread>

#include <unistd.h>

#include "app/bench_timings.h"
#include "app/commands.h"
#include "engine/core/frame_writer.h"

namespace strata::app {
namespace bench {
namespace {

namespace fs = std::filesystem;

struct EncodeBenchOptions {
  std::string size = "1920x1080";
  uint32_t frames = 60;
  unsigned threads = 0;  // 0: one per hardware thread
  std::string output;    // empty: a temporary folder, removed at the end
};

// Pictures twice a frame's width, which the frames are windows of, kPanStep pixels apart (a
// camera panning, back to the start after a frame's width): a dark gradient, a bright disc with
// noise in it (a rendered volume's look) and a row of flat bordered boxes (labels). Frames take
// turns among pictures of different noise, so that, as in a turntable, no frame is the last one
// moved: PNG and H.264 get about as much to compress as from a rendered frame.
class Panorama {
 public:
  static constexpr uint32_t kPanStep = 4;
  static constexpr uint32_t kNoises = 3;

  explicit Panorama(graph::Extent frame) : frame_(frame), width_(2 * frame.width) {
    for (uint32_t n = 0; n < kNoises; ++n) pictures_.push_back(picture(n + 1));
  }

  // Frame f: a copy of its window, as the renderer's picture is a copy of its readback.
  std::vector<uint8_t> frame(uint32_t f) const {
    const std::vector<uint8_t>& picture = pictures_[f % kNoises];
    std::vector<uint8_t> out(size_t{frame_.width} * frame_.height * 4);
    const size_t row = size_t{frame_.width} * 4;
    for (uint32_t y = 0; y < frame_.height; ++y) {
      const size_t from = (size_t{y} * width_ + size_t{f} * kPanStep % frame_.width) * 4;
      std::copy_n(picture.begin() + long(from), row, out.begin() + long(y * row));
    }
    return out;
  }

 private:
  struct Rgb {
    int r, g, b;
  };

  std::vector<uint8_t> picture(uint32_t seed) const {
    std::vector<uint8_t> pixels(size_t{width_} * frame_.height * 4);
    std::minstd_rand noise(seed);
    for (uint32_t y = 0; y < frame_.height; ++y) {
      for (uint32_t x = 0; x < width_; ++x) {
        const Rgb c = colour(x, y, int(noise() % 65) - 32);
        uint8_t* p = &pixels[(size_t{y} * width_ + x) * 4];
        p[0] = uint8_t(std::clamp(c.r, 0, 255));
        p[1] = uint8_t(std::clamp(c.g, 0, 255));
        p[2] = uint8_t(std::clamp(c.b, 0, 255));
        p[3] = 255;
      }
    }
    return pixels;
  }

  Rgb colour(uint32_t x, uint32_t y, int noise) const {
    const float h = float(frame_.height);
    const int background = 20 + int(40.0f * float(y) / h);
    const uint32_t box_x = x % 320, box_y = uint32_t(0.15f * h);
    if (box_x >= 40 && box_x < 240 && y >= box_y && y < box_y + 36) {
      const bool border = box_x < 42 || box_x >= 238 || y < box_y + 2 || y >= box_y + 34;
      return border ? Rgb{30, 30, 30} : Rgb{245, 245, 235};
    }
    const float dx = float(x) - float(frame_.width), dy = float(y) - 0.5f * h;
    const float inside = 1.0f - std::sqrt(dx * dx + dy * dy) / (0.45f * h);
    if (inside <= 0.0f) return {background, background, background + 10};
    const int shade = 60 + int(170.0f * inside) + noise;
    return {shade, shade * 9 / 10, shade * 8 / 10};
  }

  graph::Extent frame_;
  uint32_t width_;
  std::vector<std::vector<uint8_t>> pictures_;
};

struct EncodeRun {
  double seconds = 0.0;
  uintmax_t bytes = 0;  // of the files written
};

uintmax_t bytes_under(const fs::path& path) {
  if (fs::is_regular_file(path)) return fs::file_size(path);
  uintmax_t bytes = 0;
  for (const auto& entry : fs::directory_iterator(path)) bytes += entry.file_size();
  return bytes;
}

// Every frame through a FrameWriter into `output`, timed from the writer's opening to its finish.
EncodeRun encode(const Panorama& panorama, uint32_t frames, const fs::path& output,
                 const FrameWriter::Settings& settings) {
  const auto start = std::chrono::steady_clock::now();
  {
    FrameWriter writer(output, settings);
    for (uint32_t f = 0; f < frames; ++f) writer.write(panorama.frame(f));
    writer.finish();
  }
  const std::chrono::duration<double> seconds = std::chrono::steady_clock::now() - start;
  return {seconds.count(), bytes_under(output)};
}

ordered_json run_json(const EncodeRun& run, uint32_t frames) {
  return {{"seconds", run.seconds},
          {"frames_per_second", double(frames) / run.seconds},
          {"mean_bytes_a_frame", run.bytes / frames}};
}

// The folder the files go to: --output's, kept, or a temporary one, removed at the end.
struct OutputFolder {
  explicit OutputFolder(const std::string& output)
      : path(output.empty()
                 ? fs::temp_directory_path() / ("strata-bench-encode-" + std::to_string(getpid()))
                 : fs::path(output)),
        keep(!output.empty()) {
    fs::create_directories(path / "frames");
  }
  ~OutputFolder() {
    std::error_code error;
    if (!keep) fs::remove_all(path, error);
  }
  OutputFolder(const OutputFolder&) = delete;
  OutputFolder& operator=(const OutputFolder&) = delete;

  fs::path path;
  bool keep;
};

void bench_encode(const EncodeBenchOptions& o) {
  const graph::Extent size = parse_size(o.size, "--size");
  FrameWriter::Settings settings{.width = size.width,
                                 .height = size.height,
                                 .threads = o.threads ? o.threads : default_frame_threads()};
  const OutputFolder folder(o.output);
  const Panorama panorama(size);

  const EncodeRun png = encode(panorama, o.frames, folder.path / "frames", settings);
  ordered_json out;
  out["benchmark"] = "encode";
  out["width"] = size.width;
  out["height"] = size.height;
  out["frames"] = o.frames;
  out["threads"] = settings.threads;
  out["hardware_threads"] = std::thread::hardware_concurrency();
  out["png"] = run_json(png, o.frames);
  out["mp4"] = nullptr;
  out["gif"] = nullptr;
  std::fprintf(stderr, "bench encode: %u frames of %ux%u, %u thread%s: PNG %.2f frames/s", o.frames,
               size.width, size.height, settings.threads, settings.threads == 1 ? "" : "s",
               o.frames / png.seconds);
  if (VideoFile::built()) {
    settings.format = FrameWriter::Format::mp4;
    const EncodeRun mp4 = encode(panorama, o.frames, folder.path / "video.mp4", settings);
    out["mp4"] = run_json(mp4, o.frames);
    settings.format = FrameWriter::Format::gif;
    const EncodeRun gif = encode(panorama, o.frames, folder.path / "video.gif", settings);
    out["gif"] = run_json(gif, o.frames);
    std::fprintf(stderr, ", MP4 %.2f frames/s, GIF %.2f frames/s\n", o.frames / mp4.seconds,
                 o.frames / gif.seconds);
  } else {
    std::fprintf(stderr, "; MP4 and GIF not built (STRATA_VIDEO=OFF)\n");
  }
  print_report(out);
}

}  // namespace
}  // namespace bench

void add_encode_bench(CLI::App* bench) {
  auto o = std::make_shared<bench::EncodeBenchOptions>();
  CLI::App* cmd = bench->add_subcommand(
      "encode",
      "CPU only: frames/s of `strata video`'s PNG, MP4 and GIF writers on a made-up picture");
  cmd->add_option("--size", o->size, "N or WxH")->capture_default_str();
  cmd->add_option("--frames", o->frames, "frames written to each")
      ->check(whole_range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--threads", o->threads, "threads compressing PNGs (default: one per core)")
      ->check(whole_range(1, 1024));
  cmd->add_option("--output", o->output, "folder to keep the files in (default: none kept)");
  cmd->callback([o] { bench::bench_encode(*o); });
}

}  // namespace strata::app
