// Numeric options are bounded and checked: NaN, infinities and values out of range are usage
// errors (exit 2) that name the option and its range, before any file is read or anything is
// allocated; a video's duration and frame count have limits (labeling/camera_path.h).
#include <doctest/doctest.h>

#include <chrono>
#include <string>
#include <vector>

#include "gpu_fixture.h"

namespace strata {
namespace {

using test::run_strata;

const std::string kHead = STRATA_SOURCE_DIR "/assets/scenes/head.json";

struct BadOption {
  std::string args;     // the command line after `strata`
  std::string message;  // what the error must say
};

void check_usage_error(const BadOption& bad) {
  CAPTURE(bad.args);
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_strata(bad.args);
  CAPTURE(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("strata: error: " + bad.message) != std::string::npos);
  CHECK(r.output.find("bad_alloc") == std::string::npos);
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(60));
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("video_duration_and_rate_options_reject_nan_zero_negative_and_huge_values") {
    const std::string video = "video " + kHead + " -o /tmp/never.mp4 --orbit 90 ";
    for (const BadOption& bad : std::vector<BadOption>{
             {video + "--seconds 1e9", "--seconds: 1e9 is not a number in (0, 3600]"},
             {video + "--seconds 0", "--seconds: 0 is not a number in (0, 3600]"},
             {video + "--seconds -1", "--seconds: -1 is not a number in (0, 3600]"},
             {video + "--seconds nan", "--seconds: nan is not a number in (0, 3600]"},
             {video + "--fps nan", "--fps: nan is not a number in [1, 240]"},
             {video + "--fps 0", "--fps: 0 is not a number in [1, 240]"},
             {video + "--fps inf", "--fps: inf is not a number in [1, 240]"},
             {"video " + kHead + " -o /tmp/never.mp4 --orbit 1e30",
              "--orbit: 1e30 is not a number in [-36000, 36000]"},
             {video + "--label-speed nan", "--label-speed: nan is not a number in [0.001, 10]"},
             {video + "--ease-in -1", "--ease-in: -1 is not a number in [0, 10]"},
             {video + "--hold -inf", "--hold: -inf is not a number in [0, 100]"},
             {video + "--hold-cost nan", "--hold-cost: nan is not a number in [0, 1e+09]"},
             {video + "--fade 1e9", "--fade: 1e9 is not a number in [0, 60]"},
             {video + "--previous-weight -1",
              "--previous-weight: -1 is not a number in [0, 1e+06]"},
             {video + "--layer-margin nan", "--layer-margin: nan is not a number in [0, 100]"},
             {video + "--tidy-rounds 1.5", "--tidy-rounds: 1.5 is not a whole number in [0, 256]"},
         }) {
      check_usage_error(bad);
    }
  }

  TEST_CASE("every_subcommands_numeric_options_reject_nan_infinity_and_out_of_range") {
    for (const BadOption& bad : std::vector<BadOption>{
             {"render -o /tmp/never.png --size 16 --blur nan", "--blur: nan is not a whole number"},
             {"render " + kHead + " -o /tmp/never.png --tidy-rounds -1", "--tidy-rounds: -1 is"},
             {"render " + kHead + " -o /tmp/never.png --label-scale nan",
              "--label-scale: nan is not a number in [0.25, 4]"},
             {"render " + kHead + " -o /tmp/never.png --layers inf", "--layers: inf is not"},
             {"render " + kHead + " -o /tmp/never.png --frame -1", "--frame: -1 is not"},
             {"render " + kHead + " -o /tmp/never.png --window 400",
              "--window: '400' is not CENTER,WIDTH"},
             {"render " + kHead + " -o /tmp/never.png --window 40,0", "--window: '40,0' is not"},
             {"render " + kHead + " -o /tmp/never.png --window 40,80 --preset ct-bone",
              "give --preset or --window, not both"},
             {"render " + kHead + " -o /tmp/never.png --preset bone",
              "--preset: 'bone' is not a preset (ct-skin, "},
             {"render " + kHead + " -o /tmp/never.png --camera back",
              "--camera: " + kHead + ": no camera position named 'back'"},
             {"pick " + kHead + " --camera back --at 1,1",
              "--camera: " + kHead + ": no camera position named 'back'"},
             {"view " + kHead + " --frames -1", "--frames: -1 is not a whole number"},
             {"view " + kHead + " --label-scale inf", "--label-scale: inf is not"},
             {"view " + kHead + " --frames-in-flight nan", "--frames-in-flight: nan is not"},
             {"view --blur 1e12", "--blur: 1e12 is not"},
             {"bench render --step nan", "--step: nan is not a number in [0, 1000]"},
             {"bench render --step -1", "--step: -1 is not"},
             {"bench render --runs 0", "--runs: 0 is not a whole number in [1, 100000]"},
             {"bench sat --runs nan", "--runs: nan is not"},
             {"bench view --degrees 1e30", "--degrees: 1e30 is not a number in [-36000, 36000]"},
             {"bench view --frames inf", "--frames: inf is not"},
             {"bench placement --runs -5", "--runs: -5 is not"},
             {"bench soak --habuffer-slots 1e12", "--habuffer-slots: 1e12 is not"},
             {"bench soak --every nan", "--every: nan is not"},
         }) {
      check_usage_error(bad);
    }
  }

  TEST_CASE("video_path_segments_and_frame_counts_have_limits_checked_before_allocation") {
    const std::string video = "video " + kHead + " -o /tmp/never.mp4 ";
    for (const BadOption& bad : std::vector<BadOption>{
             {video + "--path front,left_1e9",
              "--path: " + kHead +
                  ": camera path 'front,left_1e9': 'left_1e9': '1e9' is not a "
                  "duration (seconds in (0, 3600])"},
             {video + "--path front,left_nan", "--path: " + kHead + ": camera path"},
             {video + "--path front,left_2000,front_2000",
              "--path: " + kHead +
                  ": camera path 'front,left_2000,front_2000': 'front_2000': "
                  "the path lasts more than 3600 s"},
             {"bench render --step 1e-9 --runs 1", "--step: 1e-09 is below 0.0625"},
             {video + "--orbit 360 --seconds 3600 --fps 240",
              "--fps: 240 frames a second for 3600 s is 864001 frames, more than 100000"},
         }) {
      check_usage_error(bad);
    }
  }
}

}  // namespace strata
