// H.264 MP4 output, checked with ffprobe (Debian's ffmpeg package): frame count, size, codec.
#include <doctest/doctest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/core/video_file.h"
#include "gpu_fixture.h"

namespace strata {
#if STRATA_VIDEO  // (a build without FFmpeg writes no MP4)
namespace {

// What ffprobe says of the file's video stream: "codec,width,height,frames".
std::string probe(const std::string& file) {
  return test::probe_video(file, "codec_name,width,height,nb_read_frames");
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("an_mp4_holds_every_frame_written_at_its_size") {
    const std::string file = test::output_dir() + "/gradient.mp4";
    const uint32_t width = 64, height = 48;
    {
      VideoFile video(file, width, height, 30.0);
      std::vector<uint8_t> rgba(size_t{width} * height * 4, 255);
      for (int f = 0; f < 12; ++f) {
        for (size_t p = 0; p < size_t{width} * height; ++p) {
          rgba[4 * p] = uint8_t((p % width) * 4 + size_t(f) * 10);  // a moving ramp
        }
        video.write(rgba);
      }
      video.finish();
    }
    CHECK(probe(file) == "h264,64,48,12");
  }

  TEST_CASE("an_mp4_of_odd_size_or_in_a_missing_folder_is_one_clear_error") {
    CHECK_THROWS_WITH_AS(VideoFile(test::output_dir() + "/odd.mp4", 63, 48, 30.0),
                         doctest::Contains("even width and height, not 63x48"), Error);
    CHECK_THROWS_WITH_AS(VideoFile("/nonexistent-dir/x.mp4", 64, 48, 30.0),
                         doctest::Contains("/nonexistent-dir/x.mp4: cannot write MP4"), Error);
  }
}
#endif

}  // namespace strata
