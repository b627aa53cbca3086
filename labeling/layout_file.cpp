// read_layout and parse_layout (labeling/layout_metrics.h): the layout files of `strata render
// --layout` and `strata video --layout-dir`, checked field by field, with the defaults that keep
// older files readable.
#include <cmath>
#include <limits>
#include <unordered_map>

#include "engine/core/json_field.h"
#include "engine/core/text_file.h"
#include "labeling/layout_metrics.h"

namespace strata {

namespace {

using nlohmann::json;

using Field = JsonField;

uint32_t image_extent(const json& value, const Field& field) {
  if (!value.is_number_unsigned() || value.get<uint64_t>() == 0 ||
      value.get<uint64_t>() > std::numeric_limits<uint32_t>::max()) {
    field.fail("expected a positive integer");
  }
  return value.get<uint32_t>();
}

int label_id(const json& value, const Field& field) {
  if (!value.is_number_integer() || value.get<int64_t>() < std::numeric_limits<int>::min() ||
      value.get<int64_t>() > std::numeric_limits<int>::max()) {
    field.fail("expected an integer");
  }
  return value.get<int>();
}

uint32_t layer(const json& value, const Field& field) {
  if (!value.is_number_unsigned() || value.get<uint64_t>() > std::numeric_limits<uint32_t>::max()) {
    field.fail("expected an integer >= 0");
  }
  return value.get<uint32_t>();
}

// render writes null for a cost that is not finite.
double cost(const json& value, const Field& field) {
  if (value.is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (!value.is_number()) field.fail("expected a number or null");
  return value.get<double>();
}

double opacity(const json& value, const Field& field) {
  if (!value.is_number() || !(value.get<double>() >= 0.0 && value.get<double>() <= 1.0)) {
    field.fail("expected a number from 0 to 1");
  }
  return value.get<double>();
}

// [x, y, width, height], width and height >= 0.
Rect box(const json& value, const Field& field) {
  const std::vector<double> numbers = json_numbers(value, field, 4);
  if (numbers[2] < 0.0 || numbers[3] < 0.0) field.fail("width and height must be >= 0");
  return {{numbers[0], numbers[1]}, {numbers[0] + numbers[2], numbers[1] + numbers[3]}};
}

// A still has none (null or absent); a frame of a sequence the seconds since the last one.
std::optional<double> seconds(const json* value, const Field& field) {
  if (!value || value->is_null()) return std::nullopt;
  if (!value->is_number() || !(value->get<double>() > 0.0) ||
      !std::isfinite(value->get<double>())) {
    field.fail("expected a number > 0 or null");
  }
  return value->get<double>();
}

bool boolean(const json& value, const Field& field) {
  if (!value.is_boolean()) field.fail("expected true or false");
  return value.get<bool>();
}

LayoutLabel read_label(const json& object, const Field& field) {
  if (!object.is_object()) field.fail("expected an object");
  LayoutLabel label;
  label.id = label_id(required(object, field, "id"), field / "id");
  const auto anchor = json_numbers(required(object, field, "anchor"), field / "anchor", 2);
  label.anchor = {anchor[0], anchor[1]};
  const Rect drawn = box(required(object, field, "box"), field / "box");
  label.box_origin = drawn.min;
  label.box_size = drawn.max - drawn.min;
  label.shown = boolean(required(object, field, "shown"), field / "shown");
  label.placed = label.shown;
  if (const json* placed = optional(object, "placed")) {
    label.placed = boolean(*placed, field / "placed");
  }
  if (const json* text = optional(object, "text")) {
    if (!text->is_string()) (field / "text").fail("expected a string");
    label.text = text->get<std::string>();
  }
  if (const json* l = optional(object, "layer")) label.layer = layer(*l, field / "layer");
  if (const json* c = optional(object, "cost")) label.cost = cost(*c, field / "cost");
  label.opacity = label.placed ? 1.0 : 0.0;
  if (const json* o = optional(object, "opacity")) label.opacity = opacity(*o, field / "opacity");
  if (const json* a = optional(object, "front_alpha"); a && !a->is_null()) {
    label.front_alpha = opacity(*a, field / "front_alpha");
  }
  if (const json* h = optional(object, "anchor_hidden"); h && !h->is_null()) {
    label.anchor_hidden = boolean(*h, field / "anchor_hidden");
  }
  label.target = drawn;
  if (const json* t = optional(object, "target")) {
    label.target = t->is_null() ? std::nullopt : std::optional(box(*t, field / "target"));
  }
  return label;
}

// A title's or legend's box: {"name": "title", "box": [x, y, width, height]}.
LayoutAnnotation read_annotation(const json& object, const Field& field) {
  if (!object.is_object()) field.fail("expected an object");
  LayoutAnnotation a;
  const json& name = required(object, field, "name");
  if (!name.is_string()) (field / "name").fail("expected a string");
  a.name = name.get<std::string>();
  a.box = box(required(object, field, "box"), field / "box");
  return a;
}

// Ids match labels across frames, so one id twice in a frame would make matching ambiguous.
void check_unique_ids(const std::vector<LayoutLabel>& labels, const Field& field) {
  std::unordered_map<int, size_t> first;
  for (size_t i = 0; i < labels.size(); ++i) {
    const auto [it, fresh] = first.emplace(labels[i].id, i);
    if (!fresh) {
      (field[i] / "id")
          .fail("duplicate id " + std::to_string(labels[i].id) + " (also labels[" +
                std::to_string(it->second) + "])");
    }
  }
}

}  // namespace

Layout parse_layout(const json& root, const std::filesystem::path& source) {
  const std::string file = source.string();
  const Field top{file, ""};
  if (!root.is_object()) top.fail("expected an object");
  Layout layout;
  layout.source = source;
  layout.width = image_extent(required(root, top, "width"), top / "width");
  layout.height = image_extent(required(root, top, "height"), top / "height");
  layout.seconds = seconds(optional(root, "seconds"), top / "seconds");
  const json& labels = required(root, top, "labels");
  const Field labels_field = top / "labels";
  if (!labels.is_array()) labels_field.fail("expected an array");
  for (size_t i = 0; i < labels.size(); ++i) {
    layout.labels.push_back(read_label(labels[i], labels_field[i]));
  }
  check_unique_ids(layout.labels, labels_field);
  if (const json* annotations = optional(root, "annotations")) {
    const Field field = top / "annotations";
    if (!annotations->is_array()) field.fail("expected an array");
    for (size_t i = 0; i < annotations->size(); ++i) {
      layout.annotations.push_back(read_annotation((*annotations)[i], field[i]));
    }
  }
  return layout;
}

Layout read_layout(const std::filesystem::path& path) {
  return parse_layout(read_json_file(path), path);
}

}  // namespace strata
