#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/label_file_writer.h"
#include "engine/scene/io/scene_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using strata::LabelAxes;

const fs::path schema = fs::path(STRATA_TEST_DATA) / "slicer-markups/markups-schema-v1.0.3.json";

fs::path test_folder(const std::string& name) {
  return strata::test::fresh_folder("label_file_writer_tests", name);
}

using strata::test::error_of;

strata::Label label(int id, std::string text, glm::vec3 anchor) {
  strata::Label result;
  result.id = id;
  result.text = std::move(text);
  result.anchor = anchor;
  return result;
}

// Non-ASCII text, a comma and quotes, and coordinates whose shortest decimals are long.
const std::vector<strata::Label> findings = {
    label(3, "Thalamus R – Ödem", {-20.5f, 12.25f, 30.0f}),
    label(4, "Caudate, left \"head\"", {15.125f, -40.0f, 8.5f}),
    label(5, "\"Pons\"", {0.0f, 25.75f, -12.5f}),
    label(6, "Fracture", {0.1f, -1234.5678f, 1e-5f}),
    label(9, "脳室", {999999.94f, -0.3333333f, 77.7f}),
};

// The same texts and anchors, in order, within 1e-6 mm (the writer promises them exactly).
void check_same(const std::vector<strata::Label>& read, const std::vector<strata::Label>& written) {
  REQUIRE(read.size() == written.size());
  for (size_t i = 0; i < read.size(); ++i) {
    CAPTURE(i);
    CHECK(read[i].text == written[i].text);
    CHECK(read[i].anchor == written[i].anchor);
    for (int axis = 0; axis < 3; ++axis)
      CHECK(std::abs(read[i].anchor[axis] - written[i].anchor[axis]) <= 1e-6f);
  }
}

const char* extension(bool fcsv) {
  return fcsv ? ".fcsv" : ".mrk.json";
}

bool python_jsonschema_present() {
  return std::system("python3 -c 'import jsonschema' >/dev/null 2>&1") == 0;
}

// What python3-jsonschema finds wrong in `file` by Slicer's published schema (draft-07): its
// message, or "" when the file is valid.
std::string slicer_schema_problem(const fs::path& file) {
  const std::string command =
      "python3 -c 'import json, sys, jsonschema\n"
      "try: jsonschema.validate(json.load(open(sys.argv[1], encoding=\"utf-8\")), "
      "json.load(open(sys.argv[2])))\n"
      "except jsonschema.ValidationError as e: print(e.message)' '" +
      file.string() + "' '" + schema.string() + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe);
  std::string output;
  std::array<char, 256> buffer{};
  while (std::fgets(buffer.data(), int(buffer.size()), pipe)) output += buffer.data();
  const int status = pclose(pipe);
  if (status != 0 && output.empty())
    output = "python3 exited with status " + std::to_string(status);
  return output;
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE(
      "written_label_files_load_with_the_same_texts_and_anchors_in_both_formats_and_systems") {
    const fs::path folder = test_folder("round_trip");
    for (const bool fcsv : {false, true}) {
      for (const LabelAxes axes : {LabelAxes::lps, LabelAxes::ras}) {
        const fs::path file =
            folder / ((axes == LabelAxes::lps ? "lps" : "ras") + std::string(extension(fcsv)));
        CAPTURE(file.string());
        strata::write_label_file(file, findings, axes);
        check_same(strata::load_label_file(file, 0), findings);
      }
    }
  }

  TEST_CASE("written_label_files_keep_every_float_anchor_exactly") {
    // Floats from 1e-6 to 1e6 mm of either sign, each written as its shortest decimal unless
    // reading that as a double first would round it to a neighbour.
    std::mt19937 random(20240611);
    std::uniform_real_distribution<float> exponent(-6.0f, 6.0f), mantissa(1.0f, 9.999f);
    std::bernoulli_distribution negative;
    const auto coordinate = [&] {
      const float value = mantissa(random) * std::pow(10.0f, std::floor(exponent(random)));
      return std::min(value, 999999.94f) * (negative(random) ? -1.0f : 1.0f);
    };
    std::vector<strata::Label> labels;
    for (int i = 0; i < 3000; ++i)
      labels.push_back(
          label(i, "p" + std::to_string(i), {coordinate(), coordinate(), coordinate()}));
    const fs::path folder = test_folder("exact");
    for (const bool fcsv : {false, true}) {
      for (const LabelAxes axes : {LabelAxes::lps, LabelAxes::ras}) {
        const fs::path file =
            folder / ((axes == LabelAxes::lps ? "lps" : "ras") + std::string(extension(fcsv)));
        CAPTURE(file.string());
        strata::write_label_file(file, labels, axes);
        const std::vector<strata::Label> read = strata::load_label_file(file);
        REQUIRE(read.size() == labels.size());
        size_t different = 0;
        for (size_t i = 0; i < read.size(); ++i) different += read[i].anchor != labels[i].anchor;
        CHECK(different == 0);
      }
    }
  }

  TEST_CASE("a_ras_markups_file_holds_the_lps_anchors_with_x_and_y_negated") {
    for (const LabelAxes axes : {LabelAxes::lps, LabelAxes::ras}) {
      const json root = json::parse(strata::markups_json_text(findings, axes));
      const json& markup = root["markups"].at(0);
      CHECK(markup["type"] == "Fiducial");
      CHECK(markup["coordinateSystem"] == (axes == LabelAxes::lps ? "LPS" : "RAS"));
      CHECK(markup["coordinateUnits"] == "mm");
      const json& points = markup["controlPoints"];
      REQUIRE(points.size() == findings.size());
      const float flip = axes == LabelAxes::ras ? -1.0f : 1.0f;
      for (size_t i = 0; i < findings.size(); ++i) {
        CAPTURE(i);
        const glm::vec3 anchor = findings[i].anchor;
        const json& position = points[i]["position"];
        REQUIRE(position.size() == 3);
        CHECK(float(position[0].get<double>()) == flip * anchor.x);
        CHECK(float(position[1].get<double>()) == flip * anchor.y);
        CHECK(float(position[2].get<double>()) == anchor.z);
        CHECK(points[i]["label"] == findings[i].text);
        CHECK(points[i]["positionStatus"] == "defined");
      }
    }
  }

  TEST_CASE("fcsv_quotes_a_text_with_a_comma_or_quote_as_slicer_does") {
    const std::string text = strata::fcsv_text(findings, LabelAxes::lps);
    CHECK(
        text.starts_with("# Markups fiducial file version = 4.11\n"
                         "# CoordinateSystem = LPS\n"
                         "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,"
                         "associatedNodeID\n"
                         "1,-20.5,12.25,30,0,0,0,1,1,1,0,Thalamus R – Ödem,,\n"
                         "2,15.125,-40,8.5,0,0,0,1,1,1,0,\"Caudate, left \"\"head\"\"\",,\n"
                         "3,0,25.75,-12.5,0,0,0,1,1,1,0,\"\"\"Pons\"\"\",,\n"));
    CHECK(strata::fcsv_text(findings, LabelAxes::ras).find("# CoordinateSystem = RAS\n") !=
          std::string::npos);
  }

  TEST_CASE("writing_labels_as_another_extension_is_one_error_naming_the_file") {
    const fs::path file = test_folder("extension") / "findings.csv";
    const std::string error = error_of([&] { strata::write_label_file(file, findings); });
    CHECK(error ==
          file.string() +
              ": cannot write labels as '.csv' (strata writes 3D Slicer markups: .mrk.json or "
              ".fcsv)");
    CHECK(!fs::exists(file));
  }

  TEST_CASE("writing_what_a_markups_file_cannot_hold_names_the_file_and_label_and_writes_nothing") {
    const fs::path folder = test_folder("refused");
    const auto error_for = [&](const strata::Label& bad, const char* name) {
      const std::vector<strata::Label> labels = {findings[0], bad};
      const std::string error = error_of([&] { strata::write_label_file(folder / name, labels); });
      CHECK(!fs::exists(folder / name));
      return error;
    };
    const float nan = std::numeric_limits<float>::quiet_NaN();
    CHECK(error_for(label(8, "far", {2e6f, 0.0f, 0.0f}), "far.mrk.json") ==
          (folder / "far.mrk.json").string() +
              ": labels[1] (id 8): anchor 2e+06 0 0 mm is outside -1e+06..1e+06");
    CHECK(error_for(label(8, "nan", {nan, 0.0f, 0.0f}), "nan.fcsv")
              .starts_with((folder / "nan.fcsv").string() + ": labels[1] (id 8): anchor nan"));
    CHECK(error_for(label(8,
                          "Latin-1 \xD6"
                          "dem",
                          {}),
                    "latin1.mrk.json") ==
          (folder / "latin1.mrk.json").string() + ": labels[1] (id 8): the text is not UTF-8");
    CHECK(error_for(label(8, "two\nlines", {}), "lines.fcsv") ==
          (folder / "lines.fcsv").string() +
              ": labels[1] (id 8): the text has a line break, which a .fcsv row cannot hold "
              "(write .mrk.json)");
    // The JSON escapes a line break, and both Slicer and strata read it back.
    const std::vector<strata::Label> lines = {label(8, "two\nlines", {1.0f, 2.0f, 3.0f})};
    strata::write_label_file(folder / "lines.mrk.json", lines);
    check_same(strata::load_label_file(folder / "lines.mrk.json"), lines);
  }

  TEST_CASE("fcsv_writer_refuses_a_nul_that_would_make_the_file_unreadable") {
    const fs::path folder = test_folder("nul");
    const std::vector<strata::Label> labels = {label(8, std::string("a\0b", 3), {1, 2, 3})};
    CHECK(error_of([&] { strata::write_label_file(folder / "nul.fcsv", labels); }) ==
          (folder / "nul.fcsv").string() +
              ": labels[0] (id 8): the text has a NUL character, which a .fcsv file cannot hold "
              "(write .mrk.json)");
    CHECK(!fs::exists(folder / "nul.fcsv"));
    // (JSON escapes it, and reads it back)
    strata::write_label_file(folder / "nul.mrk.json", labels);
    check_same(strata::load_label_file(folder / "nul.mrk.json"), labels);
  }

  TEST_CASE("a_label_file_holding_the_scenes_own_labels_adds_them_once_with_a_warning") {
    const fs::path folder = test_folder("merge");
    const fs::path scene =
        strata::test::write_file(folder / "scene.json", R"({"strata_scene": 1, "labels": [
            {"id": 7, "text": "Thalamus R – Ödem", "anchor": [-20.5, 12.25, 30]},
            {"id": 8, "text": "Pons", "anchor": [0, 25.75, -12.5]}]})");
    // (as the viewer saved labels before it kept the scene's own apart: those and one more)
    const std::vector<strata::Label> saved = {label(0, "Thalamus R – Ödem", {-20.5f, 12.25f, 30}),
                                              label(1, "Pons", {0, 25.75f, -12.5f}),
                                              label(2, "Pons", {0, 25.75f, -12.0f})};
    strata::write_label_file(folder / "saved.mrk.json", saved, LabelAxes::ras);
    const strata::Scene loaded = strata::load_scene(scene, {.labels = folder / "saved.mrk.json"});
    REQUIRE(loaded.labels.size() == 3);
    CHECK(loaded.labels[2].anchor == saved[2].anchor);
    CHECK(loaded.added_labels == 1);
    REQUIRE(loaded.warnings.size() == 1);
    CHECK(loaded.warnings[0] == (folder / "saved.mrk.json").string() +
                                    ": 2 of its labels the scene has already (the same text and "
                                    "anchor): added once");
  }

  TEST_CASE("written_markups_json_is_valid_by_slicers_published_schema") {
    if (!python_jsonschema_present()) {
      MESSAGE(
          "skipped: python3 cannot import jsonschema (scripts/setup.sh installs "
          "python3-jsonschema)");
      return;
    }
    const fs::path folder = test_folder("schema");
    for (const LabelAxes axes : {LabelAxes::lps, LabelAxes::ras}) {
      const fs::path file = folder / (axes == LabelAxes::lps ? "lps.mrk.json" : "ras.mrk.json");
      strata::write_label_file(file, findings, axes);
      CHECK(slicer_schema_problem(file) == "");
    }
    // The check can fail: without the markup's required "type" the same file is invalid.
    json broken = json::parse(strata::markups_json_text(findings, LabelAxes::lps));
    broken["markups"][0].erase("type");
    const fs::path no_type = strata::test::write_file(folder / "no_type.mrk.json", broken.dump());
    CHECK(slicer_schema_problem(no_type) == "'type' is a required property\n");
  }
}
