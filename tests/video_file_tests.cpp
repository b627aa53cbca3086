// H.264 MP4 and GIF output, checked with ffprobe and ffmpeg (Debian's ffmpeg package): frame
// count, size, codec, and a GIF's loop, frame time and colours.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/core/gif_palette.h"
#include "engine/core/png.h"
#include "engine/core/text_file.h"
#include "engine/core/video_file.h"
#include "gpu_fixture.h"

#if STRATA_VIDEO
extern "C" {
#include <libavutil/frame.h>
}
#endif

namespace strata {
#if STRATA_VIDEO  // (a build without FFmpeg writes no MP4)
namespace {

// What ffprobe says of the file's video stream: "codec,width,height,frames".
std::string probe(const std::string& file) {
  return test::probe_video(file, "codec_name,width,height,nb_read_frames");
}

// Frame f of a moving picture: a red ramp across, green by row, blue by frame (64 x 3 x 12
// colours: more than a palette holds, so it must choose).
std::vector<uint8_t> test_frame(uint32_t width, uint32_t height, int f) {
  std::vector<uint8_t> rgba(size_t{width} * height * 4, 255);
  for (size_t p = 0; p < size_t{width} * height; ++p) {
    rgba[4 * p] = uint8_t((p % width) * 4);
    rgba[4 * p + 1] = uint8_t((p / width) / 16 * 100);
    rgba[4 * p + 2] = uint8_t(f * 20);
  }
  return rgba;
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

  TEST_CASE("a_gif_holds_every_frame_loops_forever_and_keeps_its_colours") {
    const std::string file = test::output_dir() + "/gradient.gif";
    const uint32_t width = 63, height = 48;  // (any size: no chroma subsampling)
    {
      VideoFile video(file, width, height, 10.0, VideoFormat::gif);
      for (int f = 0; f < 12; ++f) video.write(test_frame(width, height, f));
      video.finish();
    }
    CHECK(probe(file) == "gif,63,48,12");
    // Each frame a tenth of a second: 1.2 s in all.
    CHECK(test::probe_video(file, "duration") == "1.200000");
    // The Netscape extension's loop count: 0, forever.
    const std::string bytes = read_file_bytes(file);
    CHECK(bytes.find(std::string("NETSCAPE2.0\x03\x01\x00\x00", 15)) != std::string::npos);
    // The last frame decoded is the picture written, but for the palette's few colours and their
    // dithering (a wrong palette errs by tens).
    const std::string last = test::output_dir() + "/gradient-last.png";
    const std::string command =
        "ffmpeg -v error -y -i '" + file + "' -vf 'select=eq(n\\,11)' -frames:v 1 '" + last + "'";
    REQUIRE(std::system(command.c_str()) == 0);
    const Rgba8Image decoded = read_png(last);
    const std::vector<uint8_t> written = test_frame(width, height, 11);
    REQUIRE(decoded.pixels.size() == written.size());
    double error = 0.0;
    for (size_t i = 0; i < written.size(); ++i)
      error += std::abs(int(decoded.pixels[i]) - int(written[i]));
    CHECK(error / double(written.size()) < 8.0);
  }

  // A clip longer than the frames held for the palette: the palette is made of the first ones,
  // which then come out, and every later frame comes out as it goes in, mapped to it.
  TEST_CASE("a_gif_palette_past_its_held_frames_maps_each_later_frame_as_it_comes") {
    const uint32_t width = 16, height = 8;
    const size_t frame_bytes = size_t{width} * height * 4;
    GifPalette palette("clip.gif", width, height, 3 * frame_bytes);
    std::vector<int> out;  // frames out after each frame in
    int mapped = 0;
    const GifPalette::FrameOut count = [&](AVFrame* frame) {
      CHECK(frame->format == AV_PIX_FMT_PAL8);
      CHECK(frame->width == int(width));
      CHECK(frame->data[1] != nullptr);  // (the palette)
      ++mapped;
    };
    for (int f = 0; f < 8; ++f) {
      palette.add(test_frame(width, height, f), count);
      out.push_back(mapped);
    }
    palette.finish(count);
    CHECK(out[0] == 0);
    CHECK(out[1] == 0);
    CHECK(out[2] >= 2);  // (the held three, but for one the filters may keep until the next)
    CHECK(out[7] >= 7);
    CHECK(mapped == 8);
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
