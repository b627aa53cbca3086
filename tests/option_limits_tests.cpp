// Numeric options are bounded and checked: NaN, infinities and values out of range are usage
// errors (exit 2) that name the option and its range, before any file is read or anything is
// allocated; a video's duration and frame count have limits (labeling/camera_path.h).
#include <doctest/doctest.h>

#include <chrono>
#include <regex>
#include <sstream>
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
             {"render " + kHead + " -o /tmp/never.png --camera nowhere",
              "--camera: " + kHead + ": no camera position named 'nowhere'"},
             {"pick " + kHead + " --camera nowhere --at 1,1",
              "--camera: " + kHead + ": no camera position named 'nowhere'"},
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

  // Read from each subcommand's --help, so that an option added later is covered too.
  TEST_CASE("every_option_that_takes_a_value_refuses_an_empty_one") {
    const std::regex value_option(R"(^\s+(?:-\w,)?(--[a-z0-9-]+) [A-Z])");
    size_t checked = 0;
    for (const std::string command :
         {"render", "video", "view", "pick", "eval", "info", "bench sat", "bench render",
          "bench placement", "bench view", "bench soak", "bench encode"}) {
      const auto help = run_strata(command + " --help");
      REQUIRE(help.exit_code == 0);
      std::istringstream lines(help.output);
      for (std::string line; std::getline(lines, line);) {
        std::smatch m;
        if (!std::regex_search(line, m, value_option)) continue;
        // (an option's own check may say it first: "--runs: '' is not a whole number",
        // "--order:  not in {scene,apollonius,optimized}")
        const auto r = run_strata(command + " " + m[1].str() + " ''");
        CAPTURE(r.output);
        CHECK(r.exit_code == 2);
        const std::string error = "strata: error: " + m[1].str() + ": ";
        CHECK((r.output.starts_with(error + "an empty value") ||
               r.output.starts_with(error + "'' is not") ||
               r.output.starts_with(error + " not in {")));
        ++checked;
      }
    }
    CHECK(checked > 100);
  }

  TEST_CASE("options_for_the_other_kind_of_input_are_usage_errors") {
    for (const BadOption& bad : std::vector<BadOption>{
             // No scene: render and view draw a test pattern, which has no volume or labels.
             {"render -o /tmp/never.png --size 16 --crop 0,0,0,1,1,1",
              "--crop: needs a scene (with none given the test pattern is drawn)"},
             {"render -o /tmp/never.png --size 16 --labels x.fcsv", "--labels: needs a scene"},
             {"render -o /tmp/never.png --size 16 --hard", "--hard: needs a scene"},
             {"view --camera front", "--camera: needs a scene"},
             {"render " + kHead + " -o /tmp/never.png --blur 3",
              "--blur: applies to the test pattern only (no scene)"},
             // A scene file names its volumes' series and frames itself.
             {"render " + kHead + " -o /tmp/never.png --series 2",
              "--series: " + kHead + " is a scene file"},
             {"render " + kHead + " -o /tmp/never.png --frame 2",
              "--frame: " + kHead + " is a scene file"},
             // A series the folder does not hold, as an unknown camera position.
             {"render " STRATA_SOURCE_DIR "/assets/cache/dicom/CT5N -o /tmp/never.png --series 99",
              "--series: " STRATA_SOURCE_DIR
              "/assets/cache/dicom/CT5N: no series '99' (SeriesNumber or SeriesInstanceUID); "
              "the folder holds: series 5"},
             // One plane an --clip and one pixel an --at: the scene after them is no value.
             {"render --clip 0,0,0,0,0,0 " + kHead + " -o /tmp/never.png",
              "--clip: '0,0,0,0,0,0': the normal (NX,NY,NZ) must not be zero"},
             {"render --clip 0,0,0,0,0,1,1 " + kHead + " -o /tmp/never.png",
              "--clip: '0,0,0,0,0,1,1' is not PX,PY,PZ,NX,NY,NZ"},
             {"pick --at 1,1 " + kHead + " --size 16 --at 99,1",
              "--at: 99,1 lies outside the 16x16 image"},
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

  // One frame picks at most 256 pixels: more --at is a usage error naming the limit, found before
  // the scene is read, and --help says so.
  TEST_CASE("pick_with_more_pixels_than_a_frame_picks_is_a_usage_error_naming_the_limit") {
    std::string at;
    for (int i = 0; i < 257; ++i) at += " --at 1,1";
    check_usage_error({"pick /nonexistent/scene.json" + at,
                       "--at: 257 pixels, at most 256 in one run (pick the rest in another run)"});
    const auto help = run_strata("pick --help");
    CHECK(help.output.find("up to 256") != std::string::npos);
  }
}

}  // namespace strata
