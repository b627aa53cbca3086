// What is written is what Slicer 5 itself writes for a point list, less what it would fill in
// anyway (display properties, measurements): the files read the same in Slicer and in strata.
#include "engine/scene/io/label_file_writer.h"

#include <array>
#include <charconv>
#include <string_view>

#include <nlohmann/json.hpp>

#include "engine/core/atomic_file.h"
#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/scene/value_limits.h"

namespace strata {
namespace {

namespace fs = std::filesystem;
using ordered_json = nlohmann::ordered_json;

// The version Slicer 5 writes; its reader takes any 1.x.y.
constexpr std::string_view markups_schema =
    "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
    "Schema/markups-schema-v1.0.3.json#";

// "labels[2] (id 7)": errors name the label by its place in the span and its id.
[[noreturn]] void fail(const Label& label, size_t index, const std::string& reason) {
  throw Error("labels[" + std::to_string(index) + "] (id " + std::to_string(label.id) +
              "): " + reason);
}

// What a markups file cannot hold, in either format. nlohmann decides what UTF-8 is, as it
// writes the JSON (and the loader reads .fcsv text by the same rules).
void check_label(const Label& label, size_t index) {
  if (const auto problem = value_limits::position_problem("anchor", glm::dvec3(label.anchor)))
    fail(label, index, *problem);
  try {
    (void)ordered_json(label.text).dump();
  } catch (const ordered_json::type_error&) {
    fail(label, index, "the text is not UTF-8");
  }
}

glm::vec3 file_position(const glm::vec3& anchor, LabelAxes axes) {
  if (axes == LabelAxes::lps) return anchor;
  return {-anchor.x, -anchor.y, anchor.z};
}

// A coordinate as the double whose shortest decimal reads back as the same float. The float's
// own shortest decimal does, unless it lies so near the midpoint to a neighbouring float that
// reading it as a double first (as the loaders do) rounds it there; then the float's exact value.
// -0 is written 0.
double exact_double(float value) {
  if (value == 0.0f) return 0.0;
  const double shortest = shortest_double(value);
  return float(shortest) == value ? shortest : double(value);
}

std::string number_text(float value) {
  std::array<char, 32> text{};
  const auto result = std::to_chars(text.data(), text.data() + text.size(), exact_double(value));
  return std::string(text.data(), result.ptr);
}

const char* system_name(LabelAxes axes) {
  return axes == LabelAxes::lps ? "LPS" : "RAS";
}

// ---- markups JSON

// Slicer stores a point's orientation in RAS and writes an LPS file's with its first two rows
// negated: the identity in RAS is diag(-1, -1, 1) there.
ordered_json identity_orientation(LabelAxes axes) {
  const double flip = axes == LabelAxes::lps ? -1.0 : 1.0;
  return {flip, 0.0, 0.0, 0.0, flip, 0.0, 0.0, 0.0, 1.0};
}

// Ids "1", "2", ... as Slicer numbers its points, so one it adds later takes the next number.
ordered_json control_point(const Label& label, size_t index, LabelAxes axes) {
  const glm::vec3 position = file_position(label.anchor, axes);
  return {
      {"id", std::to_string(index + 1)},
      {"label", label.text},
      {"description", ""},
      {"associatedNodeID", ""},
      {"position", {exact_double(position.x), exact_double(position.y), exact_double(position.z)}},
      {"orientation", identity_orientation(axes)},
      {"selected", true},
      {"locked", false},
      {"visibility", true},
      {"positionStatus", "defined"}};
}

// ---- .fcsv

// Slicer's ConvertStringToStorageFormat: quotes around a text with a comma or a quote, a quote
// inside written twice. It reads a row per line, so a line break cannot be quoted.
std::string fcsv_field(const Label& label, size_t index) {
  if (label.text.find_first_of("\r\n") != std::string::npos)
    fail(label, index,
         "the text has a line break, which a .fcsv row cannot hold (write .mrk.json)");
  // (strata's own reader refuses a text file with a NUL byte, as other tools' do)
  if (label.text.find('\0') != std::string::npos)
    fail(label, index,
         "the text has a NUL character, which a .fcsv file cannot hold (write .mrk.json)");
  if (label.text.find_first_of(",\"") == std::string::npos) return label.text;
  std::string quoted = "\"";
  for (const char c : label.text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

// id,x,y,z, the orientation as angle (degrees) and axis (an angle of 0 is none), vis, sel, lock,
// label, desc, associatedNodeID.
std::string fcsv_row(const Label& label, size_t index, LabelAxes axes) {
  const glm::vec3 position = file_position(label.anchor, axes);
  return std::to_string(index + 1) + "," + number_text(position.x) + "," + number_text(position.y) +
         "," + number_text(position.z) + ",0,0,0,1,1,1,0," + fcsv_field(label, index) + ",,\n";
}

std::string lowercase(std::string text) {
  for (char& c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return text;
}

}  // namespace

std::string markups_json_text(std::span<const Label> labels, LabelAxes axes) {
  ordered_json points = ordered_json::array();
  for (size_t i = 0; i < labels.size(); ++i) {
    check_label(labels[i], i);
    points.push_back(control_point(labels[i], i, axes));
  }
  const ordered_json markup = {{"type", "Fiducial"},
                               {"coordinateSystem", system_name(axes)},
                               {"coordinateUnits", "mm"},
                               {"locked", false},
                               {"fixedNumberOfControlPoints", false},
                               {"labelFormat", "%N-%d"},
                               {"lastUsedControlPointNumber", labels.size()},
                               {"controlPoints", std::move(points)}};
  const ordered_json root = {{"@schema", markups_schema},
                             {"markups", ordered_json::array({markup})}};
  return root.dump(4) + '\n';
}

std::string fcsv_text(std::span<const Label> labels, LabelAxes axes) {
  std::string text = std::string("# Markups fiducial file version = 4.11\n") +
                     "# CoordinateSystem = " + system_name(axes) +
                     "\n"
                     "# columns = id,x,y,z,ow,ox,oy,oz,vis,sel,lock,label,desc,associatedNodeID\n";
  for (size_t i = 0; i < labels.size(); ++i) {
    check_label(labels[i], i);
    text += fcsv_row(labels[i], i, axes);
  }
  return text;
}

void write_label_file(const fs::path& path, std::span<const Label> labels, LabelAxes axes) {
  const std::string name = lowercase(path.filename().string());
  std::string text;
  try {
    if (name.ends_with(".mrk.json")) {
      text = markups_json_text(labels, axes);
    } else if (name.ends_with(".fcsv")) {
      text = fcsv_text(labels, axes);
    } else {
      throw Error("cannot write labels as '" + path.extension().string() +
                  "' (strata writes 3D Slicer markups: .mrk.json or .fcsv)");
    }
  } catch (const Error& e) {
    throw Error(path.string() + ": " + e.what());
  }
  write_file_atomically(path, text, "the labels");
}

}  // namespace strata
