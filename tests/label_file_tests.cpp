#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "engine/core/error.h"
#include "engine/scene/io/label_file_loader.h"
#include "engine/scene/io/scene_loader.h"
#include "test_files.h"

namespace {

namespace fs = std::filesystem;

const fs::path label_data = fs::path(STRATA_TEST_DATA) / "labels";

fs::path test_folder(const std::string& name) {
  return strata::test::fresh_folder("label_file_tests", name);
}

using strata::test::error_of;
using strata::test::write_file;

struct Landmark {
  const char* text;
  glm::vec3 anchor;  // LPS; the RAS files hold (-x, -y, z)
};

// The three points every file in tests/data/labels holds (after what each file skips).
const Landmark landmarks[] = {
    {"Ventricule latéral", {-20.5f, 12.25f, 30.0f}},
    {"Caudate, left", {15.125f, -40.0f, 8.5f}},
    {"Pons \"Varolii\"", {0.0f, 25.75f, -12.5f}},
};

void check_landmarks(const std::vector<strata::Label>& labels, int first_id) {
  REQUIRE(labels.size() == 3);
  for (size_t i = 0; i < labels.size(); ++i) {
    CAPTURE(i);
    CHECK(labels[i].id == first_id + int(i));
    CHECK(labels[i].text == landmarks[i].text);
    CHECK(labels[i].anchor == landmarks[i].anchor);
    CHECK(labels[i].size == glm::vec2(0.0f));
    CHECK(labels[i].priority == 0.0f);
  }
}

std::vector<std::string> texts(const std::vector<strata::Label>& labels) {
  std::vector<std::string> result;
  for (const strata::Label& label : labels) result.push_back(label.text);
  return result;
}

}  // namespace

TEST_SUITE("loaders") {
  TEST_CASE("label_files_in_ras_and_lps_give_the_same_lps_anchors_texts_and_ids") {
    for (const char* name :
         {"landmarks_ras.mrk.json", "landmarks_lps.fcsv", "landmarks_slicer4_ras.fcsv",
          "landmarks_ras.csv", "landmarks_lps.csv"}) {
      CAPTURE(name);
      check_landmarks(strata::load_label_file(label_data / name, 7), 7);
    }
    check_landmarks(strata::load_label_file(label_data / "landmarks_lps.csv"), 0);
  }

  TEST_CASE("label_file_older_fcsv_with_coordinate_system_0_is_ras_and_1_is_lps") {
    // Slicer before 4.11 wrote the coordinate system as a number: 0 = RAS, 1 = LPS.
    check_landmarks(strata::load_label_file(label_data / "landmarks_slicer4_ras.fcsv"), 0);
    const fs::path lps = write_file(test_folder("fcsv_1") / "old.fcsv",
                                    "# Markups fiducial file version = 4.6\n"
                                    "# CoordinateSystem = 1\n"
                                    "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,"
                                    "associatedNodeID\n"
                                    "vtkMRMLMarkupsFiducialNode_0,1,2,3,0,0,0,1,1,1,0,A,,\n");
    const auto labels = strata::load_label_file(lps);
    REQUIRE(labels.size() == 1);
    CHECK(labels[0].anchor == glm::vec3(1.0f, 2.0f, 3.0f));
  }

  TEST_CASE("label_file_fcsv_uses_its_columns_line_and_names_empty_labels_after_the_file") {
    const fs::path path = write_file(test_folder("fcsv_columns") / "points.fcsv",
                                     "# CoordinateSystem = RAS\r\n"
                                     "# columns = label,x,y,z,sel,vis\r\n"
                                     "\r\n"
                                     "tip,1,2,3,1,1\r\n"
                                     ",4,5,6,1,1\r\n");
    const auto labels = strata::load_label_file(path);
    CHECK(texts(labels) == std::vector<std::string>{"tip", "points-2"});
    CHECK(labels[1].anchor == glm::vec3(-4.0f, -5.0f, 6.0f));
  }

  TEST_CASE("label_file_mrk_json_reads_fiducials_only_with_slicers_defaults") {
    const fs::path folder = test_folder("mrk_json");
    const fs::path path = write_file(folder / "brain.mrk.json", R"({
      "@schema": "https://raw.githubusercontent.com/Slicer/Slicer/main/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.4.json#",
      "markups": [
        {"type": "ROI", "controlPoints": [{"label": "corner", "position": [9, 9, 9]}]},
        {"type": "Fiducial", "name": "F", "controlPoints": [
          {"label": "no status", "position": [1, 2, 3]},
          {"label": "", "position": [4, 5, 6], "positionStatus": "defined"},
          {"label": "placing", "position": [0, 0, 0], "positionStatus": "preview"},
          {"label": "gone", "position": [0, 0, 0], "positionStatus": "missing"},
          {"label": "no position", "positionStatus": "defined"}
        ]},
        {"type": "Fiducial", "coordinateSystem": "RAS", "coordinateUnits": ["um", "UCUM", "micrometer"],
         "controlPoints": [{"position": [1000, 2000, 3000]}]},
        {"type": "Fiducial", "name": "empty"}
      ]})");
    const auto labels = strata::load_label_file(path, 1);
    // No coordinateSystem is LPS (the schema's default); an empty label is "<list>-<n>", a list
    // without a name is named after the file, as Slicer names it.
    CHECK(texts(labels) == std::vector<std::string>{"no status", "F-2", "brain-1"});
    CHECK(labels[0].anchor == glm::vec3(1.0f, 2.0f, 3.0f));
    CHECK(labels[1].anchor == glm::vec3(4.0f, 5.0f, 6.0f));
    CHECK(labels[2].anchor == glm::vec3(-1.0f, -2.0f, 3.0f));
    CHECK(labels[2].id == 3);
  }

  TEST_CASE("label_file_csv_keeps_quoted_commas_quotes_line_breaks_and_utf8") {
    const fs::path folder = test_folder("csv");
    // A byte order mark and CRLF, as spreadsheets write; a line break inside quotes is one in the
    // text, a typed backslash-n is two characters.
    const fs::path path = write_file(folder / "sheet.csv",
                                     "\xEF\xBB\xBFText, R , A ,S,notes\r\n"
                                     "\"Optic\r\nchiasm\",+1, 2 ,3,\"a, b\"\r\n"
                                     "Gyrus pr\xC3\xA9"
                                     "central\\n,-1.5e1,0,0,\r\n"
                                     ",1,1,1,\r\n"
                                     "\r\n");
    const auto labels = strata::load_label_file(path);
    CHECK(texts(labels) ==
          std::vector<std::string>{"Optic\nchiasm", "Gyrus précentral\\n", "sheet-3"});
    CHECK(labels[0].anchor == glm::vec3(-1.0f, -2.0f, 3.0f));
    CHECK(labels[1].anchor == glm::vec3(15.0f, 0.0f, 0.0f));
  }

  TEST_CASE("label_file_csv_reads_slicers_control_point_table_export") {
    const fs::path path = write_file(test_folder("csv_slicer") / "table.csv",
                                     "label,l,p,s,defined,selected,visible,locked,description\n"
                                     "F-1,-19.5,13.25,29.5,1,1,1,0,\n"
                                     "F-2,0,0,0,0,1,1,0,template point\n"
                                     "F-3,81.75,-42.5,9.625,1,1,1,0,\n");
    const auto labels = strata::load_label_file(path);
    CHECK(texts(labels) == std::vector<std::string>{"F-1", "F-3"});
    CHECK(labels[1].anchor == glm::vec3(81.75f, -42.5f, 9.625f));
    CHECK(labels[1].id == 1);
  }

  TEST_CASE("label_file_errors_name_the_file_and_reason") {
    const fs::path folder = test_folder("errors");
    const fs::path unknown = write_file(folder / "points.txt", "text,r,a,s\nA,1,2,3\n");
    CHECK(error_of([&] { strata::load_label_file(unknown); }) ==
          unknown.string() +
              ": unknown label file format '.txt' (expected .mrk.json, .fcsv or .csv)");
    const fs::path plain_json = write_file(folder / "points.json", "{}");
    CHECK(error_of([&] { strata::load_label_file(plain_json); }) ==
          plain_json.string() +
              ": unknown label file format '.json' (expected .mrk.json, .fcsv or .csv)");
    const fs::path missing = folder / "missing.csv";
    CHECK(error_of([&] { strata::load_label_file(missing); }) ==
          missing.string() + ": no such file");
  }

  TEST_CASE("label_file_csv_errors_name_the_line_column_and_reason") {
    const fs::path folder = test_folder("csv_errors");
    const std::string prefix = (folder / "l.csv").string() + ": ";
    const auto load = [&](const std::string& text) {
      const fs::path path = write_file(folder / "l.csv", text);
      return error_of([&] { strata::load_label_file(path); });
    };
    CHECK(load("") ==
          prefix + "no header row (expected e.g. text,r,a,s for RAS or text,l,p,s for LPS)");
    CHECK(load("text,r,a,s\n") == prefix + "no points");
    CHECK(load("text,x,y,z\nA,1,2,3\n") ==
          prefix +
              "line 1: no coordinate columns: name them r,a,s (RAS) or l,p,s (LPS); x,y,z do not "
              "say which system the numbers are in");
    CHECK(load("text,r,a\n") == prefix + "line 1: no 's' column");
    CHECK(load("text,l,s\n") == prefix + "line 1: no 'p' column");
    CHECK(load("name,r,a,s\n") == prefix + "line 1: no 'text' column");
    CHECK(load("text,label,r,a,s\n") ==
          prefix + "line 1: both a 'text' and a 'label' column: keep one");
    CHECK(load("text,r,a,s,l\n") ==
          prefix + "line 1: both RAS (r, a) and LPS (l, p) columns: keep one system");
    CHECK(load("text,r,R,a,s\n") == prefix + "line 1: two 'r' columns");
    CHECK(load("text,r,a,s\nA,1,2\n") == prefix + "line 2: 3 fields, the header names 4");
    CHECK(load("text,r,a,s\nCaudate, left,1,2,3\n") ==
          prefix + "line 2: 5 fields, the header names 4; a comma inside a text must be quoted");
    CHECK(load("text,r,a,s\nA,1,two,3\n") == prefix + "line 2: column 'a': 'two' is not a number");
    CHECK(load("text,r,a,s\nA,1,2,3mm\n") == prefix + "line 2: column 's': '3mm' is not a number");
    CHECK(load("text,r,a,s\nA,,2,3\n") == prefix + "line 2: column 'r': '' is not a number");
    CHECK(load("text,r,a,s\nA,1,nan,3\n") ==
          prefix + "line 2: column 'a': 'nan' is not a finite number");
    CHECK(load("text,r,a,s\nA,-inf,2,3\n") ==
          prefix + "line 2: column 'r': '-inf' is not a finite number");
    CHECK(load("text,r,a,s\nA,1,2,1e39\n") ==
          prefix + "line 2: column 's': '1e39' is out of range");
    // Line numbers count the lines inside quoted fields.
    CHECK(load("text,r,a,s\n\"two\nlines\",1,2,3\nB,1,x,3\n") ==
          prefix + "line 4: column 'a': 'x' is not a number");
    CHECK(load("text,r,a,s\n\"A,1,2,3\n") == prefix + "line 2: a quoted field is not closed");
    CHECK(load("text,r,a,s\n\"A\"B,1,2,3\n") ==
          prefix +
              "line 2: text after the closing quote of a field (a quote inside quotes is "
              "written \"\")");
    CHECK(load("text,r,a,s\ncaf\xE9,1,2,3\n") ==
          prefix + "line 2: column 'text' is not UTF-8 text (save the file as UTF-8)");
    CHECK(load("text,r,a,s,defined\nA,1,2,3,yes\n") ==
          prefix + "line 2: column 'defined': 'yes' is not 0 or 1");
  }

  TEST_CASE("label_file_fcsv_errors_name_the_line_and_reason") {
    const fs::path folder = test_folder("fcsv_errors");
    const std::string prefix = (folder / "f.fcsv").string() + ": ";
    const auto load = [&](const std::string& text) {
      const fs::path path = write_file(folder / "f.fcsv", text);
      return error_of([&] { strata::load_label_file(path); });
    };
    const std::string version = "# Markups fiducial file version = 5.6\n";
    const std::string lps = version + "# CoordinateSystem = LPS\n";
    CHECK(load(version + "1,1,2,3,0,0,0,1,1,1,0,A,,\n") ==
          prefix +
              "line 2: no '# CoordinateSystem = ' line before the points (LPS or RAS; 0 = RAS, "
              "1 = LPS before Slicer 4.11)");
    CHECK(load(version + "# CoordinateSystem = IJK\n") ==
          prefix + "line 2: CoordinateSystem 'IJK' is not LPS, RAS, 0 (RAS) or 1 (LPS)");
    CHECK(load(lps) == prefix + "no points");
    CHECK(load(lps + "1,1,2,3,0,0,0,1,1,1,0,A,,,2\n") ==
          prefix +
              "line 3: 15 fields, expected 14 (or 16, as Slicer 5 writes); a comma inside a "
              "label or description must be quoted");
    CHECK(load(lps + "1,1,2,3,0,0,0,1,1,1,0,A,,,7,0\n") ==
          prefix +
              "line 3: 16 fields, expected 14 (or 16 as Slicer 5 writes, with the position "
              "status 0, 1, 2 or 3 as the 15th, not '7'); a comma inside a label or description "
              "must be quoted");
    // Slicer 4's 14 fields with two unquoted commas in the label look like Slicer 5's 16.
    CHECK(load(lps + "1,1,2,3,0,0,0,1,1,1,0,Caudate, left, head,,\n") ==
          prefix +
              "line 3: 16 fields, expected 14 (or 16 as Slicer 5 writes, with the position "
              "status 0, 1, 2 or 3 as the 15th, not ''); a comma inside a label or description "
              "must be quoted");
    CHECK(load(lps + "1,abc,2,3,0,0,0,1,1,1,0,A,,\n") ==
          prefix + "line 3: column 'x': 'abc' is not a number");
    CHECK(load(lps + "1,1,2,inf,0,0,0,1,1,1,0,A,,\n") ==
          prefix + "line 3: column 'z': 'inf' is not a finite number");
    CHECK(load(lps + "# columns = label,x,y,z\nA,1,2\n") ==
          prefix + "line 4: 3 fields, expected 4 as the columns line names");
    CHECK(load(lps + "# columns = label,x,y\n") ==
          prefix + "line 3: the columns line names no 'z' column");
  }

  TEST_CASE("label_file_mrk_json_errors_name_the_field_and_reason") {
    const fs::path folder = test_folder("mrk_json_errors");
    const std::string prefix = (folder / "m.mrk.json").string() + ": ";
    const auto load = [&](const std::string& text) {
      const fs::path path = write_file(folder / "m.mrk.json", text);
      return error_of([&] { strata::load_label_file(path); });
    };
    const std::string schema =
        R"("@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/markups-schema-v1.0.3.json#")";
    const auto file = [&](const std::string& markups) {
      return "{" + schema + R"(, "markups": [)" + markups + "]}";
    };
    CHECK(load("{\n") ==
          prefix +
              "parse error at line 2, column 1: syntax error while parsing object key - "
              "unexpected end of input; expected string literal");
    CHECK(load(R"({"markups": []})") == prefix + "not a 3D Slicer markups file (no \"@schema\")");
    CHECK(
        load(R"({"@schema": "https://example.org/markups-schema-v2.0.0.json#", "markups": []})") ==
        prefix +
            "@schema: 'https://example.org/markups-schema-v2.0.0.json#' is not a Slicer "
            "markups schema this strata reads (markups-schema-v1.x.y.json)");
    CHECK(load("{" + schema + "}") == prefix + "missing key 'markups'");
    CHECK(load(file(R"({"name": "F"})")) == prefix + "markups[0]: missing key 'type'");
    CHECK(load(file(R"({"type": "Line", "controlPoints": [{"position": [1, 2, 3]}]})")) ==
          prefix +
              "no points (strata reads the defined control points of \"Fiducial\" markups, "
              "Slicer's point lists)");
    CHECK(load(file(R"({"type": "Fiducial", "coordinateSystem": "IJK"})")) ==
          prefix + "markups[0].coordinateSystem: 'IJK' is not LPS or RAS");
    CHECK(load(file(R"({"type": "Fiducial", "coordinateUnits": "cm"})")) ==
          prefix + "markups[0].coordinateUnits: 'cm' is not mm or um");
    CHECK(load(file(R"({"type": "Fiducial", "controlPoints":
                        [{"position": [1, 2, 3]}, {"position": [1, 2]}]})")) ==
          prefix + "markups[0].controlPoints[1].position: expected 3 numbers");
    CHECK(load(file(R"({"type": "Fiducial", "controlPoints": [{"position": [1, "2", 3]}]})")) ==
          prefix + "markups[0].controlPoints[0].position: expected 3 numbers");
    CHECK(load(file(R"({"type": "Fiducial", "controlPoints": [{"position": [1, 2, 1e39]}]})")) ==
          prefix + "markups[0].controlPoints[0].position: a coordinate is out of range");
    CHECK(load(file(
              R"({"type": "Fiducial", "controlPoints": [{"label": 5, "position": [1, 2, 3]}]})")) ==
          prefix + "markups[0].controlPoints[0].label: expected a string");
    CHECK(load(file(R"({"type": "Fiducial", "controlPoints":
                        [{"position": [1, 2, 3], "positionStatus": "placed"}]})")) ==
          prefix +
              "markups[0].controlPoints[0].positionStatus: 'placed' is not one of defined, "
              "preview, undefined, missing");
  }

  // Found with fuzz_markups_json (a 60 KB "@schema" string): std::regex matched it by recursion,
  // a stack frame per character, and overflowed the stack instead of loading or failing.
  TEST_CASE("label_file_mrk_json_reads_a_schema_of_any_length_without_overflowing_the_stack") {
    const fs::path folder = test_folder("mrk_json_long_schema");
    const auto load = [&](const std::string& schema) {
      const fs::path path = write_file(
          folder / "m.mrk.json",
          R"({"@schema": ")" + schema +
              R"(", "markups": [{"type": "Fiducial", "controlPoints": [{"position": [1, 2, 3]}]}]})");
      return error_of([&] { strata::load_label_file(path); });
    };
    const std::string long_prefix(1 << 20, 'a');
    CHECK(load(long_prefix + "/markups-schema-v1.10.22.json##") == "(no error)");
    const std::string refused = load(long_prefix);
    CHECK(refused.find("@schema: 'aaaa") != std::string::npos);
    CHECK(
        refused.ends_with("is not a Slicer markups schema this strata reads "
                          "(markups-schema-v1.x.y.json)"));
    CHECK(load("markups-schema-v1.0.3.json") == "(no error)");
    CHECK(load("markups-schema-v1.0.json") != "(no error)");
    CHECK(load("markups-schema-v1..3.json") != "(no error)");
    CHECK(load("markups-schema-v1.0.3.jsonx") != "(no error)");
    CHECK(load("markups-schema-v11.0.3.json") != "(no error)");
  }

  // The error names the label file that brings the scene past the limit, not the scene.
  TEST_CASE("label_file_past_the_label_limit_is_named_in_the_error") {
    const fs::path folder = test_folder("label_limit");
    std::string csv = "text,l,p,s\n";
    for (int i = 0; i < 5000; ++i) csv += "L," + std::to_string(i) + ",0,0\n";
    const fs::path file = write_file(folder / "points.csv", csv);
    const fs::path empty = write_file(folder / "empty.json", "{\"strata_scene\": 1}");
    CHECK(error_of([&] { strata::load_scene(empty, {.labels = file}); }) ==
          file.string() + ": 5000 labels; strata places at most 4096 in a scene");
    const fs::path three = write_file(
        folder / "three.json",
        "{\"strata_scene\": 1, \"labels\": [{\"id\": 0, \"text\": \"A\", \"anchor\": [0, 0, 0]},"
        "{\"id\": 1, \"text\": \"B\", \"anchor\": [0, 0, 0]},"
        "{\"id\": 2, \"text\": \"C\", \"anchor\": [0, 0, 0]}]}");
    const fs::path most = write_file(folder / "most.csv", csv.substr(0, csv.find("L,4094,")));
    CHECK(error_of([&] { strata::load_scene(three, {.labels = most}); }) ==
          most.string() +
              ": 4094 labels, 4097 with the scene's 3; strata places at most 4096 in a scene");
    const fs::path referring =
        write_file(folder / "referring.json", "{\"strata_scene\": 1, \"labels\": \"points.csv\"}");
    CHECK(error_of([&] { strata::load_scene(referring); }) ==
          referring.string() + ": labels: " + file.string() +
              ": 5000 labels; strata places at most 4096 in a scene");
    CHECK(strata::label_limit_problem(4096, 0) == std::nullopt);
    CHECK(strata::label_limit_problem(4000, 97) ==
          "4000 labels, 4097 with the scene's 97; strata places at most 4096 in a scene");
  }
}
