// `strata video`'s frame writer: PNG frames written on worker threads are the bytes of those
// written one after another, and an error names the first bad frame by frame order.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/core/frame_writer.h"
#include "test_files.h"

namespace strata {
namespace {

constexpr uint32_t kWidth = 48, kHeight = 32;

// Frame f: a ramp that moves with f, so no two frames are alike.
std::vector<uint8_t> frame(uint32_t f) {
  std::vector<uint8_t> rgba(size_t{kWidth} * kHeight * 4, 255);
  for (size_t p = 0; p < size_t{kWidth} * kHeight; ++p) {
    rgba[4 * p] = uint8_t(p % kWidth * 5 + f * 9);
    rgba[4 * p + 1] = uint8_t(p / kWidth * 7);
  }
  return rgba;
}

// Writes `frames` frames as PNGs into `folder` on `threads` threads; frame `bad` (if below
// frames) and every later one have a row too few.
void write_frames(const std::filesystem::path& folder, unsigned threads, uint32_t frames,
                  uint32_t bad = ~0u) {
  FrameWriter writer(folder, {.width = kWidth, .height = kHeight, .threads = threads});
  for (uint32_t f = 0; f < frames; ++f) {
    std::vector<uint8_t> rgba = frame(f);
    if (f >= bad) rgba.resize(rgba.size() - kWidth * 4);
    writer.write(std::move(rgba));
  }
  writer.finish();
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("png_frames_written_on_threads_are_the_bytes_of_frames_written_one_by_one") {
    const auto serial = test::fresh_folder("frame_writer", "serial");
    const auto threaded = test::fresh_folder("frame_writer", "threaded");
    write_frames(serial, 1, 12);
    write_frames(threaded, 3, 12);
    const auto files = test::folder_bytes(serial);
    CHECK(files.size() == 12);
    CHECK(files.count(frame_file_name(11, "png")) == 1);
    CHECK(test::folder_bytes(threaded) == files);
  }

  // What a video removes as an earlier run's frames: frame_file_name's names, nothing else.
  TEST_CASE("earlier_frames_are_the_files_named_as_frames_and_no_others") {
    const auto folder = test::fresh_folder("frame_writer", "earlier");
    for (const char* name : {"frame-00000.png", "frame-00017.png", "frame-123456.png",
                             "frame-00001.json", "frame-1.png", "frame-000001.png",
                             "frame-0000a.png", "frame-00002.png.txt", "xframe-00003.png"})
      test::write_file(folder / name, "");
    std::filesystem::create_directory(folder / "frame-00004.png");
    CHECK(frame_files_in(folder, "png") ==
          std::vector<std::filesystem::path>{folder / "frame-00000.png", folder / "frame-00017.png",
                                             folder / "frame-123456.png"});
    CHECK(frame_files_in(folder, "json") ==
          std::vector<std::filesystem::path>{folder / "frame-00001.json"});
    CHECK(frame_files_in(folder / "missing", "png").empty());
  }

  TEST_CASE("a_frame_writer_error_names_the_first_bad_frame_in_frame_order") {
    const auto folder = test::fresh_folder("frame_writer", "bad");
    for (unsigned threads : {1u, 3u}) {
      CAPTURE(threads);
      CHECK_THROWS_WITH_AS(write_frames(folder, threads, 10, 4),
                           doctest::Contains("frame-00004.png: 5952 bytes is not a 48x32"), Error);
      CHECK_THROWS_WITH_AS(write_frames(folder / "missing", threads, 6),
                           doctest::Contains("missing/frame-00000.png: cannot write PNG"), Error);
    }
  }
}

}  // namespace strata
