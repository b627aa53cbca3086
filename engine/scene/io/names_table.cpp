// Names tables (segmentation.h): the files that say what each value of a label map is. The form is
// told by content: JSON is nnU-Net's dataset.json or a MONAI bundle; a first row starting
// "LabelValue," is 3D Slicer's CSV; a data line with a quoted name is ITK-SNAP's; six columns are
// a colour table (3D Slicer's .ctbl or FreeSurfer's LUT, told apart by the comment header), two or
// three are AAL's "index name colour". Every data line must then have that form.
#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/core/text_file.h"
#include "engine/scene/io/names_table_builder.h"
#include "engine/scene/segmentation.h"

namespace strata {
namespace {

using names_table::fail;
using names_table::parse_integer;
using names_table::TableBuilder;

namespace fs = std::filesystem;
using ordered_json = nlohmann::ordered_json;

constexpr const char* kForms =
    "an ITK-SNAP label description file, a 3D Slicer colour table (.ctbl, .txt or .csv), "
    "FreeSurfer's FreeSurferColorLUT.txt, AAL's 'index name colour' list, an nnU-Net "
    "dataset.json with \"labels\" or a MONAI bundle with a \"channel_def\"";

std::string line_name(size_t line) {
  return "line " + std::to_string(line);
}

// A value or text as an error message quotes it: at most 40 bytes, control bytes as '?'.
std::string quoted(std::string_view text) {
  std::string shown(text.substr(0, 40));
  for (char& c : shown)
    if (static_cast<unsigned char>(c) < 32 || c == 127) c = '?';
  return "'" + shown + (text.size() > 40 ? "...'" : "'");
}

std::optional<double> parse_real(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size() || text.empty()) return {};
  return value;
}

// ---- line forms

std::vector<std::string_view> split_whitespace(std::string_view text) {
  std::vector<std::string_view> tokens;
  size_t pos = 0;
  while (true) {
    pos = text.find_first_not_of(" \t", pos);
    if (pos == std::string_view::npos) break;
    const size_t end = std::min(text.find_first_of(" \t", pos), text.size());
    tokens.push_back(text.substr(pos, end - pos));
    pos = end;
  }
  return tokens;
}

struct Line {
  size_t number = 0;
  std::string_view text;  // without its end of line
};

bool is_comment_or_blank(std::string_view text) {
  const size_t first = text.find_first_not_of(" \t");
  return first == std::string_view::npos || text[first] == '#';
}

std::vector<Line> split_lines(std::string_view text) {
  std::vector<Line> lines;
  size_t pos = 0, number = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    if (line.ends_with('\r')) line.remove_suffix(1);
    lines.push_back({++number, line});
    pos = end + 1;
  }
  return lines;
}

// One colour component: an integer 0..255 as the colour tables write it.
float colour_component(const fs::path& file, const Line& line, std::string_view text,
                       const char* component) {
  const auto value = parse_integer(text);
  if (!value || *value < 0 || *value > 255)
    fail(file, line_name(line.number),
         std::string(component) + " " + quoted(text) + " is not an integer 0..255");
  return float(*value) / 255.0f;
}

glm::vec3 rgb(const fs::path& file, const Line& line, std::string_view r, std::string_view g,
              std::string_view b) {
  return {colour_component(file, line, r, "red"), colour_component(file, line, g, "green"),
          colour_component(file, line, b, "blue")};
}

int64_t value_of(const fs::path& file, const Line& line, std::string_view text) {
  const auto value = parse_integer(text);
  if (!value) fail(file, line_name(line.number), "value " + quoted(text) + " is not an integer");
  return *value;
}

// ITK-SNAP: IDX -R- -G- -B- -A-- VIS MSH "LABEL"; the label is everything between the first and
// the last double quote (so it may hold spaces and quotes).
void add_itk_snap_line(TableBuilder& builder, const Line& line) {
  const size_t open = line.text.find('"'), close = line.text.rfind('"');
  const std::vector<std::string_view> fields = split_whitespace(line.text.substr(0, open));
  if (open == std::string_view::npos || close == open || fields.size() != 7 ||
      line.text.find_first_not_of(" \t", close + 1) != std::string_view::npos)
    fail(builder.file, line_name(line.number),
         "expected 'IDX R G B A VIS MSH \"LABEL\"', got " + quoted(line.text));
  const auto alpha = parse_real(fields[4]);
  if (!alpha || !(*alpha >= 0.0 && *alpha <= 1.0))
    fail(builder.file, line_name(line.number),
         "alpha " + quoted(fields[4]) + " is not a number 0..1");
  for (size_t flag : {5, 6})
    if (fields[flag] != "0" && fields[flag] != "1")
      fail(builder.file, line_name(line.number),
           std::string(flag == 5 ? "VIS " : "MSH ") + quoted(fields[flag]) + " is not 0 or 1");
  builder.add(line_name(line.number), value_of(builder.file, line, fields[0]),
              std::string(line.text.substr(open + 1, close - open - 1)),
              rgb(builder.file, line, fields[1], fields[2], fields[3]));
}

// 3D Slicer's .ctbl and FreeSurfer's LUT: value name R G B A (A may be left out).
void add_colour_table_line(TableBuilder& builder, const Line& line) {
  const std::vector<std::string_view> fields = split_whitespace(line.text);
  if (fields.size() != 5 && fields.size() != 6)
    fail(builder.file, line_name(line.number),
         "expected 'value name R G B A', got " + quoted(line.text));
  if (fields.size() == 6) colour_component(builder.file, line, fields[5], "alpha");
  builder.add(line_name(line.number), value_of(builder.file, line, fields[0]),
              std::string(fields[1]), rgb(builder.file, line, fields[2], fields[3], fields[4]));
}

// AAL (mricron): index name [colour]; the colour is a number of AAL's own, not RGB.
void add_aal_line(TableBuilder& builder, const Line& line) {
  const std::vector<std::string_view> fields = split_whitespace(line.text);
  if ((fields.size() != 2 && fields.size() != 3) || (fields.size() == 3 && !parse_real(fields[2])))
    fail(builder.file, line_name(line.number),
         "expected 'index name colour', got " + quoted(line.text));
  builder.add(line_name(line.number), value_of(builder.file, line, fields[0]),
              std::string(fields[1]));
}

enum class LineForm { itk_snap, colour_table, aal };

// The form of a file of lines, from its first data line; none when no line form fits.
std::optional<LineForm> line_form(std::string_view first_data_line) {
  if (first_data_line.find('"') != std::string_view::npos) return LineForm::itk_snap;
  const std::vector<std::string_view> fields = split_whitespace(first_data_line);
  const auto starts_as_number = [](std::string_view field) {
    return field.find_first_of("0123456789") == (field[0] == '-' || field[0] == '+' ? 1 : 0);
  };
  if (fields.empty() || !starts_as_number(fields[0])) return {};
  if (fields.size() == 5 || fields.size() == 6) return LineForm::colour_table;
  if (fields.size() == 2 || fields.size() == 3) return LineForm::aal;
  return {};
}

// Which program wrote a colour table: their comment headers say; a .ctbl is Slicer's.
std::string colour_table_format(const std::vector<Line>& lines, const fs::path& file) {
  for (const Line& line : lines) {
    if (!is_comment_or_blank(line.text)) break;
    if (line.text.find("Color table file") != std::string_view::npos)
      return "3D Slicer colour table";
    if (line.text.find("FreeSurferColorLUT") != std::string_view::npos ||
        line.text.find("#No. Label Name") != std::string_view::npos)
      return "FreeSurfer colour table";
  }
  const std::string name = file.filename().string();
  if (file.extension() == ".ctbl") return "3D Slicer colour table";
  if (name.find("ColorLUT") != std::string::npos) return "FreeSurfer colour table";
  return "colour table (value name R G B A)";
}

NamesTable parse_lines(std::string_view text, const fs::path& file) {
  const std::vector<Line> lines = split_lines(text);
  const Line* first = nullptr;
  for (const Line& line : lines)
    if (!is_comment_or_blank(line.text)) {
      first = &line;
      break;
    }
  if (!first) fail(file, "", "no entries: the names table is empty");
  const auto form = line_form(first->text);
  if (!form)
    fail(file, line_name(first->number),
         "not a names table: expected " + std::string(kForms) + "; got " + quoted(first->text));
  TableBuilder builder{file, {}, {}};
  for (const Line& line : lines) {
    if (is_comment_or_blank(line.text)) continue;
    if (*form == LineForm::itk_snap) add_itk_snap_line(builder, line);
    if (*form == LineForm::colour_table) add_colour_table_line(builder, line);
    if (*form == LineForm::aal) add_aal_line(builder, line);
  }
  if (*form == LineForm::itk_snap) return builder.finish("ITK-SNAP label descriptions");
  if (*form == LineForm::aal) return builder.finish("AAL names (index name colour)");
  return builder.finish(colour_table_format(lines, file));
}

// ---- 3D Slicer's CSV colour table

struct CsvRecord {
  size_t line = 0;  // where it starts
  std::vector<std::string> fields;
};

// RFC 4180 records: a quoted field may hold commas, line breaks and doubled quotes.
std::vector<CsvRecord> csv_records(std::string_view text, const fs::path& file) {
  std::vector<CsvRecord> records;
  size_t line = 1, pos = 0;
  while (pos < text.size()) {
    CsvRecord record{line, {""}};
    bool quoted_field = false, field_start = true;
    for (; pos < text.size(); ++pos) {
      const char c = text[pos];
      if (quoted_field) {
        if (c == '\n') ++line;
        if (c != '"') {
          record.fields.back() += c;
        } else if (pos + 1 < text.size() && text[pos + 1] == '"') {
          record.fields.back() += '"', ++pos;
        } else {
          quoted_field = false;
        }
      } else if (c == '"' && field_start) {
        quoted_field = true;
      } else if (c == ',') {
        record.fields.emplace_back();
      } else if (c == '\n') {
        break;
      } else if (c != '\r') {
        record.fields.back() += c;
      }
      field_start = c == ',' && !quoted_field;
    }
    if (quoted_field) fail(file, line_name(record.line), "a quoted field is not closed");
    ++pos, ++line;
    const bool blank = record.fields.size() == 1 &&
                       record.fields[0].find_first_not_of(" \t\r") == std::string::npos;
    if (!blank) records.push_back(std::move(record));
  }
  return records;
}

NamesTable parse_slicer_csv(std::string_view text, const fs::path& file) {
  const std::vector<CsvRecord> records = csv_records(text, file);
  const std::vector<std::string>& header = records.at(0).fields;
  const auto column = [&](std::string_view name) -> std::optional<size_t> {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return i;
    return {};
  };
  const auto value_column = column("LabelValue"), name_column = column("Name");
  const std::string header_line = line_name(records[0].line);
  if (!value_column) fail(file, header_line, "no LabelValue column");
  if (!name_column) fail(file, header_line, "no Name column: a names table needs names");
  const std::array<std::optional<size_t>, 3> colour_columns = {column("Color_R"), column("Color_G"),
                                                               column("Color_B")};
  const bool has_colour = colour_columns[0] && colour_columns[1] && colour_columns[2];
  TableBuilder builder{file, {}, {}};
  for (size_t r = 1; r < records.size(); ++r) {
    const CsvRecord& record = records[r];
    const Line line{record.line, {}};
    const auto field = [&](size_t i) -> std::string_view {
      if (i >= record.fields.size())
        fail(file, line_name(record.line),
             "expected " + std::to_string(header.size()) + " columns, got " +
                 std::to_string(record.fields.size()));
      return record.fields[i];
    };
    std::optional<glm::vec3> colour;
    if (has_colour)
      colour = rgb(file, line, field(*colour_columns[0]), field(*colour_columns[1]),
                   field(*colour_columns[2]));
    builder.add(line_name(record.line), value_of(file, line, field(*value_column)),
                std::string(field(*name_column)), colour);
  }
  return builder.finish("3D Slicer colour table (CSV)");
}

// ---- JSON: nnU-Net's dataset.json and MONAI's channel_def

// nnU-Net v2 maps names to values ("liver": 1), v1 values to names ("1": "liver"). A v2 value that
// is a list names a region of several labels (region-based training): no one voxel value has that
// name, so such entries are left out.
NamesTable parse_nnunet_labels(const ordered_json& labels, const JsonField& field,
                               const fs::path& file) {
  if (!labels.is_object()) field.fail("expected an object of label names and values");
  TableBuilder builder{file, {}, {}};
  bool v1 = false;
  for (const auto& [key, value] : labels.items()) {
    const JsonField at = field / ("'" + key + "'");
    if (value.is_string()) {
      const auto number = parse_integer(key);
      if (!number) at.fail("a v1 label's key must be its value (an integer)");
      builder.add(at.path, *number, value.get<std::string>());
      v1 = true;
    } else if (value.is_number_integer()) {
      // (a value past int64's range is simply too large)
      builder.add(at.path,
                  value.is_number_unsigned()
                      ? int64_t(std::min<uint64_t>(value.get<uint64_t>(), INT64_MAX))
                      : value.get<int64_t>(),
                  key);
    } else if (!value.is_array()) {
      at.fail("expected an integer value (or a list of them), got " + json_for_message(value));
    }
  }
  return builder.finish(v1 ? "nnU-Net dataset.json (v1)" : "nnU-Net dataset.json");
}

NamesTable parse_channel_def(const ordered_json& channels, const JsonField& field,
                             const fs::path& file) {
  if (!channels.is_object()) field.fail("expected an object of channel numbers and names");
  TableBuilder builder{file, {}, {}};
  for (const auto& [key, value] : channels.items()) {
    const JsonField at = field / ("'" + key + "'");
    const auto number = parse_integer(key);
    if (!number) at.fail("a channel's key must be its number (an integer)");
    if (!value.is_string()) at.fail("expected the channel's name, got " + json_for_message(value));
    builder.add(at.path, *number, value.get<std::string>());
  }
  return builder.finish("MONAI bundle channel_def");
}

// The "channel_def" that names the output label map. A bundle defines one for its inputs too
// ({"0": "image"}), so one under "outputs" comes first, else the first in the document. The walk
// keeps a stack and each node's parent instead of recursing or building every node's path: the
// nesting depth is the file's to choose.
std::optional<NamesTable> find_channel_def(const ordered_json& root, const fs::path& file) {
  struct Visit {
    const ordered_json* node;
    size_t parent;
    std::string key;
    bool in_outputs;
  };
  std::vector<Visit> visits = {{&root, 0, "", false}};
  std::vector<size_t> stack = {0};
  std::optional<size_t> first, in_outputs;
  while (!stack.empty() && !in_outputs) {
    const size_t index = stack.back();
    stack.pop_back();
    const ordered_json& node = *visits[index].node;
    const bool parent_in_outputs = visits[index].in_outputs;
    const size_t begin = visits.size();
    if (!node.is_structured()) continue;
    for (const auto& [key, value] : node.items()) {
      visits.push_back({&value, index, key, parent_in_outputs || key == "outputs"});
      if (!node.is_object() || key != "channel_def") continue;
      if (!first) first = visits.size() - 1;
      if (visits.back().in_outputs) in_outputs = visits.size() - 1;
    }
    for (size_t i = visits.size(); i > begin; --i) stack.push_back(i - 1);  // document order
  }
  const std::optional<size_t> chosen = in_outputs ? in_outputs : first;
  if (!chosen) return std::nullopt;
  std::string path;
  for (size_t i = *chosen; i != 0; i = visits[i].parent)
    path = visits[i].key + (path.empty() ? "" : "." + path);
  const std::string file_name = file.string();
  return parse_channel_def(*visits[*chosen].node, JsonField{file_name, path}, file);
}

NamesTable parse_json(std::string_view text, const fs::path& file) {
  ordered_json root;
  try {
    root = ordered_json::parse(text);
  } catch (const ordered_json::exception& e) {
    const std::string what = e.what();
    const size_t end = what.find("] ");
    fail(file, "", end == std::string::npos ? what : what.substr(end + 2));
  }
  const std::string file_name = file.string();
  if (root.is_object())
    if (const auto labels = root.find("labels"); labels != root.end())
      return parse_nnunet_labels(*labels, JsonField{file_name, "labels"}, file);
  if (auto table = find_channel_def(root, file)) return std::move(*table);
  fail(file, "",
       "not a names table: JSON without \"labels\" (nnU-Net) or \"channel_def\" (MONAI); "
       "expected " +
           std::string(kForms));
}

}  // namespace

NamesTable parse_names_table(std::string_view text, const std::filesystem::path& file) {
  if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);  // a UTF-8 byte order mark
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) fail(file, "", "no entries: the names table is empty");
  if (text[first] == '{' || text[first] == '[' || file.extension() == ".json")
    return parse_json(text, file);
  if (text.substr(first).starts_with("LabelValue,") ||
      text.substr(first).starts_with("\"LabelValue\","))
    return parse_slicer_csv(text, file);
  if (file.extension() == ".csv")
    fail(file, line_name(1),
         "not a names table: a CSV colour table starts with the header "
         "'LabelValue,Name,Color_R,Color_G,Color_B,Color_A'; expected " +
             std::string(kForms));
  return parse_lines(text, file);
}

namespace names_table {

void fail(const fs::path& file, const std::string& where, const std::string& reason) {
  throw Error(file.string() + ": " + (where.empty() ? "" : where + ": ") + reason);
}

std::optional<int64_t> parse_integer(std::string_view text) {
  if (text.starts_with('+')) text.remove_prefix(1);
  int64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size() || text.empty()) return {};
  return value;
}

void TableBuilder::add(const std::string& where, int64_t value, std::string name,
                       std::optional<glm::vec3> colour) {
  if (value < 0 || value > kMaxRegionValue)
    fail(file, where,
         "value " + std::to_string(value) + " is outside 0.." + std::to_string(kMaxRegionValue));
  if (name.empty()) fail(file, where, "value " + std::to_string(value) + " has no name");
  try {
    (void)ordered_json(name).dump();  // nlohmann refuses text that is not UTF-8
  } catch (const ordered_json::type_error&) {
    fail(file, where, "the name is not UTF-8 text (save the file as UTF-8)");
  }
  const auto [it, added] = where_first.emplace(int(value), where);
  if (!added)
    fail(file, where,
         "value " + std::to_string(value) + " is named twice (first at " + it->second + ")");
  table.entries.push_back({int(value), std::move(name), colour});
}

NamesTable TableBuilder::finish(std::string format) {
  if (table.entries.empty()) fail(file, "", "no entries: the names table is empty");
  table.format = std::move(format);
  return std::move(table);
}

}  // namespace names_table

NamesTable load_names_table(const std::filesystem::path& path) {
  return parse_names_table(read_text_file(path), path);
}

}  // namespace strata
