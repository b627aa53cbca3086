// Slicer's files state their coordinate system (.mrk.json per markup, .fcsv in a header line) and
// strata's CSV states it in its column names. Nothing is guessed: a label anchored on the wrong
// side of the patient is worse than an error.
#include "engine/scene/io/label_file_loader.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/core/text_file.h"
#include "engine/scene/value_limits.h"

namespace strata {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Field = JsonField;

enum class Axes { lps, ras };

// A line of a text file, for errors "<file>: line 3: <reason>".
struct FileLine {
  const std::string& file;
  int number = 0;

  [[noreturn]] void fail(const std::string& reason) const {
    throw Error(file + ": line " + std::to_string(number) + ": " + reason);
  }
};

std::string lowercase(std::string_view text) {
  std::string result(text);
  for (char& c : result) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return result;
}

std::string_view trim(std::string_view text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

// The name before the first dot, as Slicer names a point list after its file: "head.mrk.json"
// is "head".
std::string base_name(const fs::path& path) {
  const std::string name = path.filename().string();
  return name.substr(0, name.find('.'));
}

// An empty label becomes "<list>-<n>", Slicer's default label format "%N-%d".
std::string fallback_text(const std::string& list_name, size_t index) {
  return list_name + "-" + std::to_string(index + 1);
}

// Text from a file written in another encoding (Latin-1 from a spreadsheet) would draw as
// replacement characters; saying so is kinder.
bool is_utf8(std::string_view text) {
  constexpr std::array<uint32_t, 5> smallest = {0, 0, 0x80, 0x800, 0x10000};
  size_t i = 0;
  while (i < text.size()) {
    const auto lead = static_cast<unsigned char>(text[i]);
    const size_t length = lead < 0x80           ? 1
                          : (lead >> 5) == 0x6  ? 2
                          : (lead >> 4) == 0xE  ? 3
                          : (lead >> 3) == 0x1E ? 4
                                                : 0;
    if (length == 0 || i + length > text.size()) return false;
    uint32_t code = length == 1 ? lead : lead & (0x7Fu >> length);
    for (size_t k = 1; k < length; ++k) {
      const auto next = static_cast<unsigned char>(text[i + k]);
      if ((next & 0xC0) != 0x80) return false;
      code = (code << 6) | (next & 0x3Fu);
    }
    // Overlong forms, UTF-16 surrogates and code points past U+10FFFF are not UTF-8.
    if (code < smallest[length] || (code >= 0xD800 && code <= 0xDFFF) || code > 0x10FFFF)
      return false;
    i += length;
  }
  return true;
}

bool fits_float(double value) {
  return std::isfinite(value) && std::abs(value) <= double(std::numeric_limits<float>::max());
}

// strata's world is LPS, like DICOM and ITK; RAS has the first two axes the other way.
glm::vec3 to_world(const glm::dvec3& position, Axes axes) {
  if (axes == Axes::lps) return glm::vec3(position);
  return glm::vec3(glm::dvec3(-position.x, -position.y, position.z));
}

// The labels read, each with where it is in its file ("line 4", "markups[0].controlPoints[2]")
// for errors found after reading (an id past int's range).
struct ReadLabels {
  std::vector<Label> labels;
  std::vector<std::string> places;
  std::vector<std::string> systems;  // the coordinate systems the points were written in

  void add(Label label, std::string place, Axes axes) {
    labels.push_back(std::move(label));
    places.push_back(std::move(place));
    const std::string system = axes == Axes::ras ? "RAS" : "LPS";
    if (std::find(systems.begin(), systems.end(), system) == systems.end())
      systems.push_back(system);
  }
};

std::optional<std::string> anchor_problem(const Label& label) {
  return value_limits::position_problem("anchor", glm::dvec3(label.anchor));
}

// ---- CSV (.fcsv and .csv)

// One record of a CSV file, or a whole '#' line where the format has comments (.fcsv).
struct Row {
  int line = 0;  // where the record starts
  bool comment = false;
  std::vector<std::string> fields;  // a comment: its text after the '#'
};

// RFC 4180: a quoted field may hold commas, quotes written twice and line breaks (kept as '\n',
// also when the file ends lines with CRLF). A quote inside an unquoted field is an ordinary
// character, as Slicer reads it. Blank lines are skipped.
std::vector<Row> csv_rows(const std::string& text, const std::string& file, bool comments) {
  enum class State { start, unquoted, quoted, closed };
  std::vector<Row> rows;
  const size_t n = text.size();
  size_t i = text.starts_with("\xEF\xBB\xBF") ? 3 : 0;  // the byte order mark spreadsheets write
  int line = 1;
  while (i < n) {
    if (text[i] == '\n' || text.compare(i, 2, "\r\n") == 0) {
      i += text[i] == '\n' ? 1 : 2;
      ++line;
      continue;
    }
    Row row{.line = line};
    if (comments && text[i] == '#') {
      const size_t end = std::min(text.find('\n', i), n);
      std::string_view body(text.data() + i + 1, end - i - 1);
      if (body.ends_with('\r')) body.remove_suffix(1);
      row.comment = true;
      row.fields.emplace_back(body);
      rows.push_back(std::move(row));
      i = end + 1;
      ++line;
      continue;
    }
    State state = State::start;
    std::string field;
    bool row_ended = false;
    while (i < n && !row_ended) {
      const char c = text[i++];
      const bool crlf = c == '\r' && i < n && text[i] == '\n';
      if (state == State::quoted) {
        if (c == '"' && i < n && text[i] == '"') {
          field += '"';
          ++i;
        } else if (c == '"') {
          state = State::closed;
        } else if (!crlf) {  // the '\n' of a CRLF comes next
          field += c;
          if (c == '\n') ++line;
        }
      } else if (c == ',') {
        row.fields.push_back(std::move(field));
        field.clear();
        state = State::start;
      } else if (c == '\n' || crlf) {
        if (crlf) ++i;
        ++line;
        row_ended = true;
      } else if (state == State::closed) {
        FileLine{file, line}.fail(
            "text after the closing quote of a field (a quote inside quotes is written \"\")");
      } else if (c == '"' && state == State::start) {
        state = State::quoted;
      } else {
        field += c;
        state = State::unquoted;
      }
    }
    if (state == State::quoted) FileLine{file, row.line}.fail("a quoted field is not closed");
    row.fields.push_back(std::move(field));
    rows.push_back(std::move(row));
  }
  return rows;
}

// A coordinate: a finite number that a float holds ('+' allowed, surrounding spaces ignored).
double coordinate(std::string_view field, const std::string& column, const FileLine& line) {
  const std::string_view text = trim(field);
  const std::string_view number = text.starts_with('+') ? text.substr(1) : text;
  double value = 0.0;
  const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
  const std::string what = "column '" + column + "': '" + std::string(text) + "' ";
  const bool parsed = error == std::errc{} || error == std::errc::result_out_of_range;
  if (number.empty() || number.starts_with('-') != text.starts_with('-') || !parsed ||
      end != number.data() + number.size())
    line.fail(what + "is not a number");
  if (!std::isfinite(value) && error == std::errc{}) line.fail(what + "is not a finite number");
  if (error != std::errc{} || !fits_float(value)) line.fail(what + "is out of range");
  return value;
}

std::string text_field(const std::string& field, const std::string& column, const FileLine& line) {
  if (!is_utf8(field))
    line.fail("column '" + column + "' is not UTF-8 text (save the file as UTF-8)");
  return field;
}

std::vector<std::string> column_names(const Row& header) {
  std::vector<std::string> names;
  for (const std::string& field : header.fields) names.push_back(lowercase(trim(field)));
  return names;
}

// The index of column `name`, if there is one; an error if there are two.
std::optional<size_t> find_column(const std::vector<std::string>& names, std::string_view name,
                                  const FileLine& line) {
  std::optional<size_t> found;
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] != name) continue;
    if (found) line.fail("two '" + std::string(name) + "' columns");
    found = i;
  }
  return found;
}

// ---- Slicer's fiducial list (.fcsv)

// The columns every Slicer since 4.4 writes; Slicer 5 appends positionStatus and autoCreated to
// each row without naming them in the columns line.
constexpr std::array<std::string_view, 14> slicer_columns = {
    "id", "x",   "y",   "z",    "ow",    "ox",   "oy",
    "oz", "vis", "sel", "lock", "label", "desc", "associatednodeid"};
constexpr size_t slicer_position_status = 14;

struct FcsvLayout {
  size_t x = 1, y = 2, z = 3;
  std::optional<size_t> label = 11;
  size_t count = slicer_columns.size();
  bool slicer = true;  // Slicer's own layout, so rows may carry Slicer 5's two extra fields
};

FcsvLayout fcsv_layout(std::string_view columns, const FileLine& line) {
  Row header;
  header.fields.emplace_back();
  for (const char c : columns) {
    if (c == ',')
      header.fields.emplace_back();
    else
      header.fields.back() += c;
  }
  const std::vector<std::string> names = column_names(header);
  const auto index = [&](std::string_view name) {
    const auto found = find_column(names, name, line);
    if (!found) line.fail("the columns line names no '" + std::string(name) + "' column");
    return *found;
  };
  return {.x = index("x"),
          .y = index("y"),
          .z = index("z"),
          .label = find_column(names, "label", line),
          .count = names.size(),
          .slicer =
              std::equal(names.begin(), names.end(), slicer_columns.begin(), slicer_columns.end())};
}

// Slicer writes "LPS" or "RAS"; before Slicer 4.11 it wrote the numbers 0 (RAS) and 1 (LPS).
Axes fcsv_axes(std::string_view value, const FileLine& line) {
  const std::string name = lowercase(value);
  if (name == "lps" || name == "1") return Axes::lps;
  if (name == "ras" || name == "0") return Axes::ras;
  line.fail("CoordinateSystem '" + std::string(value) + "' is not LPS, RAS, 0 (RAS) or 1 (LPS)");
}

// A comma in an unquoted label or description splits it into two fields.
constexpr std::string_view quote_commas = "; a comma inside a label or description must be quoted";

// Slicer 5's position status: 0 undefined, 1 preview, 2 defined, 3 missing. A row of 16 fields
// with another 15th is most likely a Slicer 4 row with two commas in its text.
bool fcsv_defined(std::string_view field, const FileLine& line) {
  const std::string_view status = trim(field);
  if (status == "2") return true;
  if (status == "0" || status == "1" || status == "3") return false;
  line.fail(
      "16 fields, expected 14 (or 16 as Slicer 5 writes, with the position status 0, 1, 2 "
      "or 3 as the 15th, not '" +
      std::string(status) + "')" + std::string(quote_commas));
}

ReadLabels read_fcsv(const fs::path& path, const std::string& text) {
  const std::string file = path.string();
  std::optional<Axes> axes;
  FcsvLayout layout;
  ReadLabels labels;
  size_t point_index = 0;
  for (const Row& row : csv_rows(text, file, true)) {
    const FileLine line{file, row.line};
    if (row.comment) {
      const std::string_view body = row.fields[0];
      const size_t equals = body.find('=');
      if (equals == std::string_view::npos) continue;
      const std::string key = lowercase(trim(body.substr(0, equals)));
      const std::string_view value = trim(body.substr(equals + 1));
      if (key == "coordinatesystem") axes = fcsv_axes(value, line);
      if (key == "columns") layout = fcsv_layout(value, line);
      continue;
    }
    if (!axes) {
      line.fail(
          "no '# CoordinateSystem = ' line before the points (LPS or RAS; 0 = RAS, 1 = LPS before "
          "Slicer 4.11)");
    }
    const size_t count = row.fields.size();
    const bool slicer5 = layout.slicer && count == layout.count + 2;
    if (count != layout.count && !slicer5) {
      line.fail(std::to_string(count) + " fields, expected " + std::to_string(layout.count) +
                (layout.slicer ? " (or 16, as Slicer 5 writes)" : " as the columns line names") +
                std::string(count > layout.count ? quote_commas : ""));
    }
    const size_t index = point_index++;
    if (slicer5 && !fcsv_defined(row.fields[slicer_position_status], line)) continue;
    const glm::dvec3 position(coordinate(row.fields[layout.x], "x", line),
                              coordinate(row.fields[layout.y], "y", line),
                              coordinate(row.fields[layout.z], "z", line));
    Label label;
    label.anchor = to_world(position, *axes);
    if (const auto problem = anchor_problem(label)) line.fail(*problem);
    if (layout.label) label.text = text_field(row.fields[*layout.label], "label", line);
    if (label.text.empty()) label.text = fallback_text(base_name(path), index);
    labels.add(std::move(label), "line " + std::to_string(row.line), *axes);
  }
  return labels;
}

// ---- strata's CSV

// The coordinate columns' names state the system, as in Slicer's control point tables: r, a, s
// (RAS) or l, p, s (LPS). x, y, z would not say which.
struct CsvLayout {
  size_t text = 0;
  std::array<size_t, 3> axes{};
  Axes system = Axes::lps;
  std::optional<size_t> defined;
  size_t count = 0;
};

CsvLayout csv_layout(const Row& header, const std::string& file) {
  const FileLine line{file, header.line};
  const std::vector<std::string> names = column_names(header);
  const auto find = [&](std::string_view name) { return find_column(names, name, line); };
  const auto text = find("text");
  const auto label = find("label");  // Slicer's name for it in exported tables
  if (text && label) line.fail("both a 'text' and a 'label' column: keep one");
  if (!text && !label) line.fail("no 'text' column");
  const auto r = find("r"), a = find("a"), l = find("l"), p = find("p"), s = find("s");
  if ((r || a) && (l || p)) line.fail("both RAS (r, a) and LPS (l, p) columns: keep one system");
  if (!r && !a && !l && !p) {
    line.fail(std::string("no coordinate columns: name them r,a,s (RAS) or l,p,s (LPS)") +
              (find("x") ? "; x,y,z do not say which system the numbers are in" : ""));
  }
  const bool ras = r || a;
  const auto first = ras ? r : l;
  const auto second = ras ? a : p;
  for (const auto& [column, name] :
       {std::pair{first, ras ? "r" : "l"}, std::pair{second, ras ? "a" : "p"}, std::pair{s, "s"}}) {
    if (!column) line.fail(std::string("no '") + name + "' column");
  }
  return {.text = text ? *text : *label,
          .axes = {*first, *second, *s},
          .system = ras ? Axes::ras : Axes::lps,
          .defined = find("defined"),
          .count = names.size()};
}

// Slicer's exported tables mark a point without a position with defined = 0.
bool csv_defined(std::string_view field, const FileLine& line) {
  const std::string_view value = trim(field);
  if (value == "1") return true;
  if (value == "0") return false;
  line.fail("column 'defined': '" + std::string(value) + "' is not 0 or 1");
}

ReadLabels read_csv(const fs::path& path, const std::string& text) {
  const std::string file = path.string();
  const std::vector<Row> rows = csv_rows(text, file, false);
  if (rows.empty()) {
    throw Error(file + ": no header row (expected e.g. text,r,a,s for RAS or text,l,p,s for LPS)");
  }
  const CsvLayout layout = csv_layout(rows[0], file);
  const std::vector<std::string> names = column_names(rows[0]);
  ReadLabels labels;
  for (size_t i = 1; i < rows.size(); ++i) {
    const Row& row = rows[i];
    const FileLine line{file, row.line};
    if (row.fields.size() != layout.count) {
      line.fail(std::to_string(row.fields.size()) + " fields, the header names " +
                std::to_string(layout.count) +
                (row.fields.size() > layout.count ? "; a comma inside a text must be quoted" : ""));
    }
    if (layout.defined && !csv_defined(row.fields[*layout.defined], line)) continue;
    glm::dvec3 position(0.0);
    for (int axis = 0; axis < 3; ++axis) {
      const size_t column = layout.axes[size_t(axis)];
      position[axis] = coordinate(row.fields[column], names[column], line);
    }
    Label label;
    label.anchor = to_world(position, layout.system);
    if (const auto problem = anchor_problem(label)) line.fail(*problem);
    label.text = text_field(row.fields[layout.text], names[layout.text], line);
    if (label.text.empty()) label.text = fallback_text(base_name(path), i - 1);
    labels.add(std::move(label), "line " + std::to_string(row.line), layout.system);
  }
  return labels;
}

// ---- Slicer markups JSON (.mrk.json)

std::string string(const json& value, const Field& field) {
  if (!value.is_string()) field.fail("expected a string");
  return value.get<std::string>();
}

// Whether `schema` ends "markups-schema-v1.X.Y.json", then any '#'. Read from the end by hand:
// std::regex matched ".*" by recursion, a stack frame per character, and a long "@schema"
// overflowed the stack.
bool is_schema_v1(std::string_view schema) {
  while (schema.ends_with('#')) schema.remove_suffix(1);
  if (!schema.ends_with(".json")) return false;
  schema.remove_suffix(5);
  for (int number = 0; number < 2; ++number) {  // Y, then X, each after a dot
    // All digits: find_last_not_of gives npos, and npos + 1 wraps to 0.
    const size_t digits = schema.size() - (schema.find_last_not_of("0123456789") + 1);
    if (digits == 0) return false;
    schema.remove_suffix(digits);
    if (!schema.ends_with('.')) return false;
    schema.remove_suffix(1);
  }
  return schema.ends_with("markups-schema-v1");
}

// Slicer reads every schema version 1.x.y: control points kept their shape since 1.0.0.
void check_schema(const json& root, const Field& field) {
  if (!root.is_object() || !root.contains("@schema"))
    field.fail("not a 3D Slicer markups file (no \"@schema\")");
  const Field schema_field = field / "@schema";
  const std::string schema = string(root["@schema"], schema_field);
  if (!is_schema_v1(schema)) {
    schema_field.fail("'" + schema +
                      "' is not a Slicer markups schema this strata reads "
                      "(markups-schema-v1.x.y.json)");
  }
}

// The schema's default is LPS, and Slicer reads a markup without "coordinateSystem" as LPS.
Axes markup_axes(const json* system, const Field& field) {
  if (!system) return Axes::lps;
  const std::string name = string(*system, field);
  if (name == "LPS") return Axes::lps;
  if (name == "RAS") return Axes::ras;
  field.fail("'" + name + "' is not LPS or RAS");
}

// Millimetres unless the markup says micrometres; the schema allows a UCUM code or an array
// [code, "UCUM", meaning].
double units_per_millimetre(const json* units, const Field& field) {
  if (!units) return 1.0;
  const json& code = units->is_array() && !units->empty() ? (*units)[0] : *units;
  if (!code.is_string()) field.fail("expected \"mm\", \"um\" or [code, \"UCUM\", meaning]");
  const std::string name = code.get<std::string>();
  if (name == "mm") return 1.0;
  if (name == "um") return 1000.0;
  field.fail("'" + name + "' is not mm or um");
}

// Only "defined" positions (the default) are where the user put the point; "preview" is one being
// placed, "undefined" and "missing" have none.
bool markup_defined(const json* status, const Field& field) {
  if (!status) return true;
  const std::string value = string(*status, field);
  if (value == "defined") return true;
  if (value == "preview" || value == "undefined" || value == "missing") return false;
  field.fail("'" + value + "' is not one of defined, preview, undefined, missing");
}

// A point list ("Fiducial") gives one label per defined control point. Other types (Line,
// Angle, Curve, ClosedCurve, Plane, ROI) are skipped: their points shape a figure, and a label on
// each would name corners, not places.
void read_markup(const json& markup, const Field& field, const std::string& file_name,
                 ReadLabels& labels) {
  if (!markup.is_object()) field.fail("expected an object");
  if (string(required(markup, field, "type"), field / "type") != "Fiducial") return;
  const json* name = optional(markup, "name");
  std::string list_name = name ? string(*name, field / "name") : "";
  if (list_name.empty()) list_name = file_name;  // Slicer names the list after its file
  const Axes axes = markup_axes(optional(markup, "coordinateSystem"), field / "coordinateSystem");
  const double units =
      units_per_millimetre(optional(markup, "coordinateUnits"), field / "coordinateUnits");
  const json* points = optional(markup, "controlPoints");
  if (!points) return;
  const Field points_field = field / "controlPoints";
  if (!points->is_array()) points_field.fail("expected an array");
  for (size_t i = 0; i < points->size(); ++i) {
    const json& point = (*points)[i];
    const Field point_field = points_field[i];
    if (!point.is_object()) point_field.fail("expected an object");
    if (!markup_defined(optional(point, "positionStatus"), point_field / "positionStatus"))
      continue;
    // Slicer, too, takes a point without a position as undefined.
    const json* position_json = optional(point, "position");
    if (!position_json) continue;
    const std::vector<double> v = json_numbers(*position_json, point_field / "position", 3);
    const glm::dvec3 position = glm::dvec3(v[0], v[1], v[2]) / units;
    if (!fits_float(position.x) || !fits_float(position.y) || !fits_float(position.z))
      (point_field / "position").fail("a coordinate is out of range");
    Label label;
    label.anchor = to_world(position, axes);
    if (const auto problem = anchor_problem(label)) (point_field / "position").fail(*problem);
    const json* text = optional(point, "label");
    if (text) label.text = string(*text, point_field / "label");
    if (label.text.empty()) label.text = fallback_text(list_name, i);
    labels.add(std::move(label), point_field.path, axes);
  }
}

ReadLabels read_markups(const fs::path& path) {
  const std::string file = path.string();
  const json root = read_json_file(path);
  const Field field{file, ""};
  check_schema(root, field);
  const json& markups = required(root, field, "markups");
  const Field markups_field = field / "markups";
  if (!markups.is_array()) markups_field.fail("expected an array");
  ReadLabels labels;
  for (size_t i = 0; i < markups.size(); ++i)
    read_markup(markups[i], markups_field[i], base_name(path), labels);
  return labels;
}

}  // namespace

std::vector<Label> load_label_file(const fs::path& path, int64_t first_id) {
  return read_label_file(path, first_id).labels;
}

std::optional<std::string> label_limit_problem(size_t in_file, size_t in_scene) {
  if (in_file + in_scene <= size_t(kMaxLabels)) return std::nullopt;
  return std::to_string(in_file) + " labels" +
         (in_scene == 0 ? std::string()
                        : ", " + std::to_string(in_file + in_scene) + " with the scene's " +
                              std::to_string(in_scene)) +
         "; strata places at most " + std::to_string(kMaxLabels) + " in a scene";
}

LabelFile read_label_file(const fs::path& path, int64_t first_id) {
  const std::string name = lowercase(path.filename().string());
  ReadLabels labels;
  std::string none = "no points";
  if (name.ends_with(".mrk.json")) {
    labels = read_markups(path);
    none +=
        " (strata reads the defined control points of \"Fiducial\" markups, Slicer's point "
        "lists)";
  } else if (name.ends_with(".fcsv")) {
    labels = read_fcsv(path, read_text_file(path));
  } else if (name.ends_with(".csv")) {
    labels = read_csv(path, read_text_file(path));
  } else {
    throw Error(path.string() + ": unknown label file format '" + path.extension().string() +
                "' (expected .mrk.json, .fcsv or .csv)");
  }
  if (labels.labels.empty()) throw Error(path.string() + ": " + none);
  constexpr int64_t largest = std::numeric_limits<int>::max();
  for (size_t i = 0; i < labels.labels.size(); ++i) {
    const int64_t id = first_id + int64_t(i);
    if (id > largest)
      throw Error(path.string() + ": " + labels.places[i] + ": label id " + std::to_string(id) +
                  " is past the largest, " + std::to_string(largest) +
                  " (this file's ids start at " + std::to_string(first_id) +
                  ", after the labels before it)");
    labels.labels[i].id = int(id);
  }
  return {std::move(labels.labels), std::move(labels.systems)};
}

}  // namespace strata
