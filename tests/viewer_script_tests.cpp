// The viewer's input scripts are checked: the parser (app/viewer/script.h) refuses NaN,
// infinities and numbers outside each command's range with FILE:LINE, and `strata view` stops on
// such a line with that error in bounded time instead of hanging.
#include <doctest/doctest.h>

#include <chrono>
#include <string>
#include <vector>

#include "app/viewer/script.h"
#include "engine/core/error.h"
#include "engine/scene/scene.h"
#include "gpu_fixture.h"
#include "test_files.h"

namespace strata {
namespace {

using app::parse_viewer_script;

// The Error a one-line script gives after a valid first line (so the line number is 2).
std::string parse_error(const std::string& line) {
  try {
    parse_viewer_script("key r\n" + line + "\n", "demo.txt");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// The tester's lines that hung or were accepted, and others of the same kind.
const std::vector<std::string> kBadNumbers = {
    "drag left nan nan 10 10",
    "drag left 0 0 inf 10",
    "drag left 0 0 1e30 10",
    "frames -1",
    "frames nan",
    "frames 1.5",
    "frames 1e9",
    "sleep nan",
    "sleep -1",
    "sleep inf",
    "scroll nan",
    "scroll 1e30",
    "hide -1",
    "show nan",
    "preset ct-bone -1",
    "settle-limit 0",
    "settle-limit nan",
};

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("viewer_script_parser_refuses_nan_infinite_and_out_of_range_numbers_with_file_line") {
    for (const std::string& line : kBadNumbers) {
      CAPTURE(line);
      const std::string error = parse_error(line);
      CHECK(error.rfind("demo.txt:2: '", 0) == 0);
      CHECK(error.find("is not a") != std::string::npos);
    }
    CHECK(parse_error("frames -1") == "demo.txt:2: '-1' is not a whole number in [0, 100000]");
    CHECK(parse_error("sleep nan") == "demo.txt:2: 'nan' is not a number in [0, 600]");
  }

  TEST_CASE("viewer_script_parser_reads_commands_with_their_lines_and_numbers") {
    const auto commands = parse_viewer_script(
        "# a comment\ndrag middle 1 2 3.5 4 shift\n\nframes 12  # twelve\nsleep 0.25\n"
        "set weights.label_shadow 50\nkey f12\nquit\n",
        "s.txt");
    REQUIRE(commands.size() == 6);
    CHECK(commands[0].line == 2);
    CHECK(commands[0].name == "drag");
    CHECK(commands[0].word == "middle");
    CHECK(commands[0].numbers == std::vector<double>{1, 2, 3.5, 4});
    CHECK(commands[0].flag);
    CHECK(commands[1].line == 4);
    CHECK(commands[1].numbers == std::vector<double>{12});
    CHECK(commands[2].numbers == std::vector<double>{0.25});
    CHECK(commands[3].word == "weights.label_shadow");
    CHECK(commands[3].value == "50");
    CHECK(commands[5].name == "quit");
  }

  // The label commands: place, move, text (one quoted word with spaces, '#', escaped quotes and
  // UTF-8), delete, undo, redo, save FILE [lps|ras]; their bad forms are errors with FILE:LINE.
  TEST_CASE("viewer_script_parser_reads_the_label_commands_and_quoted_text") {
    const auto c = parse_viewer_script(
        "place 80 40\nmove 101 90.5 45\ntext 101 \"Thalamus R – Ödem # \\\"rechts\\\"\" # a "
        "comment\ndelete 103\nundo\nredo\nsave a.mrk.json ras\nsave b.fcsv\n",
        "demo.txt");
    REQUIRE(c.size() == 8);
    CHECK(c[0].name == "place");
    CHECK(c[0].numbers == std::vector<double>{80.0, 40.0});
    CHECK(c[1].name == "move");
    CHECK(c[1].numbers == std::vector<double>{101.0, 90.5, 45.0});
    CHECK(c[2].name == "text");
    CHECK(c[2].value == "Thalamus R – Ödem # \"rechts\"");
    CHECK(c[3].name == "delete");
    CHECK(c[4].name == "undo");
    CHECK(c[5].name == "redo");
    CHECK(c[6].name == "save");
    CHECK(c[6].word == "a.mrk.json");
    CHECK(c[6].value == "ras");
    CHECK(c[7].value == "lps");
    CHECK(parse_error("text 3 \"open").find("demo.txt:2: a quoted text has no closing") == 0);
    CHECK(parse_error("text 3 \"\"").find("demo.txt:2: 'text' needs a text") == 0);
    CHECK(parse_error("text 3 two words").find("demo.txt:2: 'text' takes the form") == 0);
    CHECK(parse_error("place -1 4").find("demo.txt:2: '-1' is not a number") == 0);
    CHECK(parse_error("delete 1.5").find("demo.txt:2: '1.5' is not a whole number") == 0);
    CHECK(parse_error("save a.mrk.json xyz").find("demo.txt:2: 'save' takes the form") == 0);
  }

  TEST_CASE("viewer_script_parser_reads_the_crop_box") {
    const auto c = parse_viewer_script("crop -100 -120 -60 100 120 40.5\ncrop off\n", "demo.txt");
    REQUIRE(c.size() == 2);
    CHECK(c[0].name == "crop");
    CHECK(c[0].numbers == std::vector<double>{-100, -120, -60, 100, 120, 40.5});
    CHECK(c[1].name == "crop");
    CHECK(c[1].numbers.empty());
    CHECK(parse_error("crop 0 0 0 1 1").find("demo.txt:2: 'crop' takes the form") == 0);
    CHECK(parse_error("crop 0 0 5 1 1 4").find("demo.txt:2: 'crop': each low corner") == 0);
    CHECK(parse_error("crop 0 0 0 1 1 nan").find("demo.txt:2: 'nan' is not a number") == 0);
  }

  TEST_CASE("viewer_script_parser_reads_the_clipping_plane") {
    const auto c = parse_viewer_script("clip 0 -15 2.5 0 0 -1\nclip off\n", "demo.txt");
    REQUIRE(c.size() == 2);
    CHECK(c[0].name == "clip");
    CHECK(c[0].numbers == std::vector<double>{0, -15, 2.5, 0, 0, -1});
    CHECK(c[1].name == "clip");
    CHECK(c[1].numbers.empty());
    CHECK(parse_error("clip 0 0 0 1").find("demo.txt:2: 'clip' takes the form") == 0);
    CHECK(parse_error("clip 0 0 0 0 0 0").find("demo.txt:2: 'clip': the normal") == 0);
    CHECK(parse_error("clip 0 0 0 0 0 inf").find("demo.txt:2: 'inf' is not a number") == 0);
  }

  // --clip's rule: a normal no longer than 1e-6 gives no direction.
  TEST_CASE("viewer_script_clip_refuses_the_normals_that_clip_option_calls_zero") {
    const std::string zero = "demo.txt:2: 'clip': the normal (NX NY NZ) must not be zero";
    CHECK(parse_error("clip 0 0 0 1e-7 0 0").find(zero) == 0);
    CHECK(parse_error("clip 0 0 0 0 -1e-7 1e-7").find(zero) == 0);
    CHECK(parse_viewer_script("clip 0 0 0 1e-5 0 0\n", "demo.txt").size() == 1);
    CHECK(!clip_normal_usable({1e-7f, 0.0f, 0.0f}));
    CHECK(clip_normal_usable({1e-5f, 0.0f, 0.0f}));
  }

  // A command is one entry of the table (app/viewer/script_commands.inc): `report camera` and
  // `report FILE` share a name, the first entry whose words fit reads the line.
  TEST_CASE("viewer_script_report_camera_is_one_entry_of_the_command_table") {
    const auto c = parse_viewer_script("report camera\nreport r.json\n", "demo.txt");
    REQUIRE(c.size() == 2);
    CHECK(c[0].name == "report");
    CHECK(c[0].word.empty());
    CHECK(c[0].spec().writes == nullptr);
    CHECK(c[1].word == "r.json");
    CHECK(c[1].spec().writes != nullptr);
    CHECK(parse_error("report").find("demo.txt:2: 'report' takes the form: report camera | report "
                                     "FILE.json") == 0);
  }

  // docs/viewer.md lists every command of the table with its form.
  TEST_CASE("viewer_script_commands_are_each_in_the_viewer_docs") {
    const std::string docs = test::read_file(STRATA_SOURCE_DIR "/docs/viewer.md");
    for (const app::ScriptCommandSpec& spec : app::viewer_script_commands()) {
      CAPTURE(spec.name);
      std::string form;  // (a table cell writes '|' as '\|')
      for (const char ch : app::script_form(spec))
        form += ch == '|' ? std::string("\\|") : std::string(1, ch);
      CHECK(docs.find("`" + form + "`") != std::string::npos);
    }
  }

  TEST_CASE("viewer_script_parser_refuses_unknown_names_before_anything_runs") {
    CHECK(parse_error("key ctrl").find("demo.txt:2: no key 'ctrl'") == 0);
    CHECK(parse_error("drag wheel 0 0 1 1").find("demo.txt:2: no mouse button 'wheel'") == 0);
    CHECK(parse_error("view behind").find("demo.txt:2: no view 'behind'") == 0);
    CHECK(parse_error("preset glass").find("demo.txt:2: no transfer-function preset") == 0);
    CHECK(parse_error("quit now").find("demo.txt:2: 'quit' takes the form") == 0);
  }
}

TEST_SUITE("window") {
  // Each line that hung or was accepted before: the viewer stops with FILE:LINE well within the
  // time limit (a tiny window; all but render.step are found before the window opens).
  TEST_CASE("viewer_stops_on_bad_script_numbers_with_file_line_in_bounded_time") {
    const auto dir = test::fresh_folder("viewer", "bad-numbers");
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"drag left nan nan 10 10", "'nan' is not a number"},
        {"frames -1", "'-1' is not a whole number in [0, 100000]"},
        {"frames nan", "'nan' is not a whole number"},
        {"sleep nan", "'nan' is not a number in [0, 600]"},
        {"set weights.label_shadow -5",
         "parameter weights.label_shadow: -5 is not a number in [0, 1e+09]"},
        {"set forces.fade nan", "parameter forces.fade: 'nan' is not a number"},
        {"set render.step 1e-9", "parameter render.step: 1e-09 is below"},
        {"place 0 0", "nothing under the pixel to place a label on (background)"},
        {"move 3 0 0", "nothing under the pixel to move label 3 to"},
    };
    for (const auto& [line, message] : cases) {
      CAPTURE(line);
      const auto script = test::write_file(dir / "script.txt", "frames 1\n" + line + "\nquit\n");
      const auto start = std::chrono::steady_clock::now();
      const auto r = test::run_strata("view " STRATA_SOURCE_DIR
                                      "/assets/scenes/head.json --size 48x32 "
                                      "--no-panel --script " +
                                      script.string());
      CAPTURE(r.output);
      CHECK(r.exit_code == 1);
      CHECK(r.output.find("strata: error: " + script.string() + ":2: " + message) !=
            std::string::npos);
      // (a bound against waiting for ever, not a speed target: far above the run's own time on a
      // loaded 2-core machine)
      CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(180));
    }
  }

  // A step whose view does not settle within the settle limit stops the script with its line and
  // what was still busy, instead of waiting for ever (the first line runs once the first frames
  // settled, under --settle-limit; after the drag the labels glide for about 9 s of the frames'
  // time before they settle, far past the limit of 2 s).
  TEST_CASE("viewer_script_stops_when_the_view_does_not_settle_within_the_limit") {
    const auto dir = test::fresh_folder("viewer", "settle-limit");
    const auto script = test::write_file(dir / "script.txt",
                                         "settle-limit 2\ndrag left 20 60 180 60\nkey r\nquit\n");
    const auto start = std::chrono::steady_clock::now();
    const auto r = test::run_strata("view " STRATA_SOURCE_DIR
                                    "/assets/scenes/head.json --size 200x150 "
                                    "--no-panel --frame-budget 0 --settle-limit 60 --script " +
                                    script.string());
    CAPTURE(r.output);
    CHECK(r.exit_code == 1);
    CHECK(r.output.find("strata: error: " + script.string() +
                        ":3: the view did not settle within 2 s (--settle-limit, "
                        "settle-limit); still busy: ") != std::string::npos);
    CHECK(r.output.find("moving or fading (") != std::string::npos);
    // (a bound against waiting for ever, not a speed target: far above the run's own time on a
    // loaded 2-core machine)
    CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(180));
  }
}

}  // namespace strata
