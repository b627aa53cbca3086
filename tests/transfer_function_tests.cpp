#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "engine/core/error.h"
#include "engine/scene/io/transfer_function_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;

fs::path output_folder() {
  const fs::path folder = fs::path(STRATA_TEST_OUTPUT) / "transfer_function_tests";
  fs::create_directories(folder);
  return folder;
}

fs::path write_file(const std::string& name, const std::string& text) {
  return strata::test::write_file(output_folder() / name, text);
}

using strata::test::error_of;

void check_stop(const strata::TransferFunction::Stop& stop, float position, int r, int g, int b,
                int a) {
  CHECK(stop.position == position);
  CHECK(stop.color.r == float(r) / 255.0f);
  CHECK(stop.color.g == float(g) / 255.0f);
  CHECK(stop.color.b == float(b) / 255.0f);
  CHECK(stop.color.a == float(a) / 255.0f);
}

const char* const gradient_head =
    "<!DOCTYPE Gradient>\n<gradientData spread=\"PadSpread\" type=\"LinearGradient\">\n";

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("gra_import_keeps_each_stops_position_colour_and_alpha") {
    const fs::path path = fs::path(STRATA_TEST_DATA) / "voly-labeller/transferfunctions/dice4.gra";
    const strata::TransferFunction tf = strata::load_transfer_function(path);
    CHECK(tf.name == "dice4");
    CHECK(tf.source == path);
    REQUIRE(tf.stops.size() == 6);
    // The file's stops, <colorData g r a b> reordered to r, g, b, a.
    check_stop(tf.stops[0], 0.0f, 0, 0, 0, 0);
    check_stop(tf.stops[1], 0.074979f, 10, 10, 10, 0);
    check_stop(tf.stops[2], 0.1f, 24, 255, 0, 22);
    check_stop(tf.stops[3], 0.139686f, 255, 255, 255, 54);
    check_stop(tf.stops[4], 0.478333f, 95, 95, 95, 4);
    check_stop(tf.stops[5], 0.5f, 255, 255, 255, 0);
  }

  TEST_CASE("every_published_gra_file_imports") {
    const fs::path folder = fs::path(STRATA_TEST_DATA) / "voly-labeller/transferfunctions";
    int count = 0;
    for (const auto& entry : fs::directory_iterator(folder)) {
      CAPTURE(entry.path());
      const strata::TransferFunction tf = strata::load_transfer_function(entry.path());
      CHECK(!tf.stops.empty());
      ++count;
    }
    CHECK(count >= 19);
    // A hand-edited file writes alpha "0.9" on the 0..255 scale; it reads as that number.
    const strata::TransferFunction lidc = strata::load_transfer_function(folder / "LIDC_IDRI.gra");
    REQUIRE(lidc.stops.size() == 9);
    CHECK(lidc.stops[3].color.a == 0.9f / 255.0f);
  }

  TEST_CASE("transfer_function_json_round_trip_keeps_every_stop") {
    strata::TransferFunction tf;
    tf.name = "head";
    tf.stops = {{0.0f, {0.0f, 0.0f, 0.0f, 0.0f}},
                {0.1f, {0.1f, 0.2f, 0.3f, 0.4f}},
                {0.1f, {1.0f, 0.5f, 0.25f, 0.125f}},  // equal positions: a hard edge
                {1.0f, {1.0f, 1.0f, 1.0f, 1.0f}}};
    const fs::path path = output_folder() / "head.json";
    strata::write_transfer_function_json(path, tf);
    const strata::TransferFunction back = strata::load_transfer_function(path);
    CHECK(back.name == "head");
    CHECK(back.source == path);
    REQUIRE(back.stops.size() == tf.stops.size());
    for (size_t i = 0; i < tf.stops.size(); ++i) {
      CAPTURE(i);
      CHECK(back.stops[i].position == tf.stops[i].position);
      for (int c = 0; c < 4; ++c) CHECK(back.stops[i].color[c] == tf.stops[i].color[c]);
    }
    CHECK(strata::is_transfer_function_file(path));
    CHECK(back.units.empty());
    // In the volume's values (HU): positions beyond 0..1 and the units kept.
    strata::TransferFunction hu = tf;
    hu.units = "HU";
    hu.stops[0].position = -1000.0f;
    hu.stops[1].position = -500.0f;
    hu.stops[2].position = 40.0f;
    hu.stops[3].position = 1800.0f;
    strata::write_transfer_function_json(output_folder() / "hu.json", hu);
    const strata::TransferFunction hu_back =
        strata::load_transfer_function(output_folder() / "hu.json");
    CHECK(hu_back.units == "HU");
    CHECK(hu_back.stops[1].position == -500.0f);
    CHECK(hu_back.stops[3].position == 1800.0f);
    // Floats are written with the fewest digits that read back the same.
    std::ifstream in(path);
    const std::string text{std::istreambuf_iterator<char>(in), {}};
    CHECK(text.find("0.1,") != std::string::npos);
    CHECK(text.find("0.100000") == std::string::npos);
  }

  TEST_CASE("sample_interpolates_linearly_between_stops_and_clamps_outside") {
    strata::TransferFunction tf;
    tf.stops = {{0.25f, {0.0f, 0.0f, 0.0f, 0.0f}},
                {0.75f, {1.0f, 0.5f, 0.0f, 1.0f}},
                {0.75f, {0.0f, 0.0f, 1.0f, 1.0f}},
                {1.0f, {0.0f, 0.0f, 0.0f, 1.0f}}};
    CHECK(tf.sample(0.0f) == glm::vec4(0.0f));
    CHECK(tf.sample(0.25f) == glm::vec4(0.0f));
    const glm::vec4 middle = tf.sample(0.5f);
    CHECK(middle.r == doctest::Approx(0.5));
    CHECK(middle.g == doctest::Approx(0.25));
    CHECK(middle.a == doctest::Approx(0.5));
    CHECK(tf.sample(0.875f).b == doctest::Approx(0.5));
    CHECK(tf.sample(2.0f) == glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    CHECK(strata::TransferFunction{}.sample(0.5f) == glm::vec4(0.0f));
  }

  TEST_CASE("malformed_gra_files_give_one_error_naming_the_file_and_reason") {
    const fs::path broken = write_file("broken.gra", std::string(gradient_head) +
                                                         " <stopData position=\"0\">\n"
                                                         "  <colorData r=\"1\" g=\"2\"\n");
    std::string message = error_of([&] { strata::load_transfer_function(broken); });
    CHECK(message.find(broken.string() + ": XML error at line ") == 0);

    const fs::path no_alpha = write_file(
        "no_alpha.gra", std::string(gradient_head) +
                            "<stopData position=\"0.5\"><colorData r=\"1\" g=\"2\" b=\"3\"/>"
                            "</stopData></gradientData>");
    CHECK(error_of([&] { strata::load_transfer_function(no_alpha); }) ==
          no_alpha.string() + ": stopData[0].colorData: missing attribute 'a'");

    const fs::path out_of_range = write_file(
        "range.gra", std::string(gradient_head) +
                         "<stopData position=\"1.5\"><colorData r=\"1\" g=\"2\" b=\"3\" a=\"4\"/>"
                         "</stopData></gradientData>");
    CHECK(error_of([&] { strata::load_transfer_function(out_of_range); }) ==
          out_of_range.string() + ": stopData[0]: position is '1.5', expected a number in [0, 1]");

    // NaN compares false with both bounds; it is no position (it overran the table when sampled).
    const fs::path nan = write_file(
        "nan.gra", std::string(gradient_head) +
                       "<stopData position=\"0\"><colorData r=\"1\" g=\"2\" b=\"3\" a=\"4\"/>"
                       "</stopData><stopData position=\"nan\"><colorData r=\"1\" g=\"2\" "
                       "b=\"3\" a=\"nan\"/></stopData></gradientData>");
    CHECK(error_of([&] { strata::load_transfer_function(nan); }) ==
          nan.string() + ": stopData[1]: position is 'nan', expected a number in [0, 1]");

    const fs::path channel = write_file(
        "channel.gra", std::string(gradient_head) +
                           "<stopData position=\"0\"><colorData r=\"256\" g=\"2\" b=\"3\" a=\"4\"/>"
                           "</stopData></gradientData>");
    CHECK(error_of([&] { strata::load_transfer_function(channel); }) ==
          channel.string() +
              ": stopData[0].colorData: attribute 'r' is '256', expected a number 0..255");

    const fs::path empty = write_file("empty.gra", std::string(gradient_head) + "</gradientData>");
    CHECK(error_of([&] { strata::load_transfer_function(empty); }) ==
          empty.string() + ": gradientData: no <stopData> stops");

    const fs::path other = write_file("other.gra", "<svg/>");
    CHECK(error_of([&] { strata::load_transfer_function(other); }) ==
          other.string() + ": not a Qt gradient file (no <gradientData> element)");
  }

  TEST_CASE("transfer_function_json_errors_name_the_file_and_field") {
    const auto load_text = [](const std::string& name, const std::string& text) {
      const fs::path path = write_file(name, text);
      return error_of([&] { strata::load_transfer_function(path); });
    };
    const std::string folder = output_folder().string() + "/";
    CHECK(load_text("syntax.json", "{\n  \"strata_transfer_function\": 1,\n  \"stops\": [,]\n}") ==
          folder +
              "syntax.json: parse error at line 3, column 13: syntax error while parsing value - "
              "unexpected ','; expected '[', '{', or a literal");
    CHECK(load_text("version.json", R"({"strata_transfer_function": 2, "stops": []})") ==
          folder +
              "version.json: strata_transfer_function: version 2 is not supported (this strata "
              "reads version 1)");
    CHECK(load_text("key.json", R"({"strata_transfer_function": 1, "stop": []})") ==
          folder +
              "key.json: unknown key 'stop' (expected strata_transfer_function, name, units, "
              "stops)");
    CHECK(
        load_text("units.json", R"({"strata_transfer_function": 1, "units": "mm", "stops": []})") ==
        folder +
            "units.json: units: expected \"HU\" or \"raw\" (positions in the volume's values) or "
            "\"range\" (0..1 of its value range, the default)");
    CHECK(load_text("hu.json", R"({"strata_transfer_function": 1, "units": "HU",
            "stops": [{"position": "a", "color": [1, 1, 1, 1]}]})") ==
          folder + "hu.json: stops[0].position: expected a value of the volume (|v| <= 1e9)");
    CHECK(
        load_text(
            "color.json",
            R"({"strata_transfer_function": 1, "stops": [{"position": 0, "color": [1, 1, 1]}]})") ==
        folder + "color.json: stops[0].color: expected 4 numbers [r, g, b, a] in [0, 1]");
    CHECK(
        load_text(
            "unit.json",
            R"({"strata_transfer_function": 1, "stops": [{"position": 0, "color": [1, 1, 1, 255]}]})") ==
        folder + "unit.json: stops[0].color: expected a number in [0, 1], got 255");
    CHECK(load_text("order.json", R"({"strata_transfer_function": 1, "stops": [
            {"position": 0.5, "color": [1, 1, 1, 1]}, {"position": 0.25, "color": [1, 1, 1, 1]}]})") ==
          folder +
              "order.json: stops[1].position: stops must be sorted by position (this one is "
              "before the previous one)");
    CHECK(load_text("scene.json", R"({"strata_scene": 1})") ==
          folder +
              "scene.json: not a strata transfer function (no \"strata_transfer_function\": 1)");
    const fs::path missing = output_folder() / "missing.gra";
    CHECK(error_of([&] { strata::load_transfer_function(missing); }) ==
          missing.string() + ": no such file");
    const fs::path unknown = write_file("tf.txt", "");
    CHECK(error_of([&] { strata::load_transfer_function(unknown); }) ==
          unknown.string() + ": unknown transfer-function format '.txt' (expected .json or .gra)");
  }

  // Found by fuzz_transfer_function_json: nlohmann-json throws out_of_range, not parse_error, for
  // a number beyond a double's range, and that escaped as an exception other than strata::Error.
  TEST_CASE("transfer_function_json_with_a_number_beyond_double_range_is_an_error") {
    const fs::path path = write_file(
        "huge.json",
        R"({"strata_transfer_function": 1, "stops": [{"position": 1e400, "color": [0, 0, 0, 0]}]})");
    CHECK(error_of([&] { strata::load_transfer_function(path); }) ==
          path.string() + ": number overflow parsing '1e400'");
  }

  // Found beside the fuzz targets (their inputs, at most 64 KiB, nest too shallowly): the version's
  // error message dumped the value, and nlohmann's dump() recurses once per level of nesting.
  TEST_CASE("transfer_function_json_with_a_deeply_nested_version_is_an_error") {
    const size_t depth = 1'000'000;
    const fs::path path =
        write_file("deep.json", R"({"strata_transfer_function": )" + std::string(depth, '[') +
                                    std::string(depth, ']') + R"(, "stops": []})");
    CHECK(error_of([&] { strata::load_transfer_function(path); }) ==
          path.string() +
              ": strata_transfer_function: version [...] is not supported (this strata reads "
              "version 1)");
  }
}
