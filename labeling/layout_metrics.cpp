#include "labeling/layout_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "engine/core/error.h"
#include "engine/core/json_field.h"
#include "engine/core/text_file.h"

namespace strata {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

using Field = JsonField;

uint32_t image_extent(const json& value, const Field& field) {
  if (!value.is_number_unsigned() || value.get<uint64_t>() == 0 ||
      value.get<uint64_t>() > std::numeric_limits<uint32_t>::max()) {
    field.fail("expected a positive integer");
  }
  return value.get<uint32_t>();
}

std::vector<double> numbers(const json& value, const Field& field, size_t count) {
  return json_numbers(value, field, count);
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

LayoutLabel read_label(const json& object, const Field& field) {
  if (!object.is_object()) field.fail("expected an object");
  LayoutLabel label;
  label.id = label_id(required(object, field, "id"), field / "id");
  const auto anchor = numbers(required(object, field, "anchor"), field / "anchor", 2);
  label.anchor = {anchor[0], anchor[1]};
  const auto box = numbers(required(object, field, "box"), field / "box", 4);
  if (box[2] < 0.0 || box[3] < 0.0) (field / "box").fail("width and height must be >= 0");
  label.box_origin = {box[0], box[1]};
  label.box_size = {box[2], box[3]};
  const json& shown = required(object, field, "shown");
  if (!shown.is_boolean()) (field / "shown").fail("expected true or false");
  label.shown = shown.get<bool>();
  label.placed = label.shown;
  if (const json* placed = optional(object, "placed")) {
    if (!placed->is_boolean()) (field / "placed").fail("expected true or false");
    label.placed = placed->get<bool>();
  }
  if (const json* text = optional(object, "text")) {
    if (!text->is_string()) (field / "text").fail("expected a string");
    label.text = text->get<std::string>();
  }
  if (const json* l = optional(object, "layer")) label.layer = layer(*l, field / "layer");
  if (const json* c = optional(object, "cost")) label.cost = cost(*c, field / "cost");
  return label;
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

Layout read_layout(const std::filesystem::path& path) {
  const json root = read_json_file(path);
  const std::string file = path.string();
  const Field top{file, ""};
  if (!root.is_object()) top.fail("expected an object");
  Layout layout;
  layout.source = path;
  layout.width = image_extent(required(root, top, "width"), top / "width");
  layout.height = image_extent(required(root, top, "height"), top / "height");
  const json& labels = required(root, top, "labels");
  const Field labels_field = top / "labels";
  if (!labels.is_array()) labels_field.fail("expected an array");
  for (size_t i = 0; i < labels.size(); ++i) {
    layout.labels.push_back(read_label(labels[i], labels_field[i]));
  }
  check_unique_ids(layout.labels, labels_field);
  return layout;
}

// --- Geometry ---

namespace {

// Twice the signed area of the triangle (a, b, c): > 0 when c lies left of a→b (y up).
double orientation(glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

bool strictly_opposite(double u, double v) {
  return (u < 0.0 && v > 0.0) || (u > 0.0 && v < 0.0);
}

}  // namespace

Rect box_of(const LayoutLabel& label) {
  return {label.box_origin, label.box_origin + label.box_size};
}

glm::dvec2 closest_point(const Rect& rect, glm::dvec2 p) {
  return glm::clamp(p, rect.min, rect.max);
}

std::optional<Segment> leader_of(const LayoutLabel& label) {
  const glm::dvec2 end = closest_point(box_of(label), label.anchor);
  if (end == label.anchor) return std::nullopt;
  return Segment{label.anchor, end};
}

double intersection_area(const Rect& r, const Rect& s) {
  const glm::dvec2 extent = glm::min(r.max, s.max) - glm::max(r.min, s.min);
  return std::max(extent.x, 0.0) * std::max(extent.y, 0.0);
}

bool segments_cross(const Segment& s, const Segment& t) {
  return strictly_opposite(orientation(s.a, s.b, t.a), orientation(s.a, s.b, t.b)) &&
         strictly_opposite(orientation(t.a, t.b, s.a), orientation(t.a, t.b, s.b));
}

// Liang-Barsky against the open rectangle: per axis, the parameters t where the segment is
// strictly between the two edges form an open interval; the segment enters the interior when
// those intervals and [0, 1] have a point in common.
bool segment_enters_interior(const Segment& s, const Rect& rect) {
  const glm::dvec2 d = s.b - s.a;
  double enter = 0.0, leave = 1.0;
  for (int axis = 0; axis < 2; ++axis) {
    if (d[axis] == 0.0) {
      if (!(rect.min[axis] < s.a[axis] && s.a[axis] < rect.max[axis])) return false;
      continue;
    }
    const double t0 = (rect.min[axis] - s.a[axis]) / d[axis];
    const double t1 = (rect.max[axis] - s.a[axis]) / d[axis];
    enter = std::max(enter, std::min(t0, t1));
    leave = std::min(leave, std::max(t0, t1));
  }
  return enter < leave;
}

bool strictly_inside(const Rect& rect, glm::dvec2 p) {
  return rect.min.x < p.x && p.x < rect.max.x && rect.min.y < p.y && p.y < rect.max.y;
}

// --- Per frame ---

namespace {

// The labels the picture draws (placed), legible or not.
std::vector<const LayoutLabel*> drawn_labels(const Layout& layout) {
  std::vector<const LayoutLabel*> shown;
  for (const LayoutLabel& l : layout.labels) {
    if (l.placed || l.shown) shown.push_back(&l);  // (shown implies placed)
  }
  return shown;
}

void count_overlaps(const std::vector<const LayoutLabel*>& shown, FrameMetrics& m) {
  for (size_t i = 0; i < shown.size(); ++i) {
    for (size_t j = i + 1; j < shown.size(); ++j) {
      const double area = intersection_area(box_of(*shown[i]), box_of(*shown[j]));
      if (area <= 0.0) continue;
      ++m.overlaps;
      m.overlap_area += area;
    }
  }
}

void count_leader_crossings(const std::vector<const LayoutLabel*>& shown, FrameMetrics& m) {
  for (size_t i = 0; i < shown.size(); ++i) {
    const auto li = leader_of(*shown[i]);
    if (!li) continue;
    for (size_t j = i + 1; j < shown.size(); ++j) {
      const auto lj = leader_of(*shown[j]);
      if (!lj || !segments_cross(*li, *lj)) continue;
      ++m.leader_crossings;
      if (shown[i]->layer == shown[j]->layer) ++m.leader_crossings_same_layer;
    }
  }
}

bool leader_through_other_box(const LayoutLabel& label,
                              const std::vector<const LayoutLabel*>& shown) {
  const auto leader = leader_of(label);
  if (!leader) return false;
  return std::any_of(shown.begin(), shown.end(), [&](const LayoutLabel* other) {
    return other != &label && segment_enters_interior(*leader, box_of(*other));
  });
}

bool anchor_covered(const LayoutLabel& label, const std::vector<const LayoutLabel*>& shown) {
  return std::any_of(shown.begin(), shown.end(), [&](const LayoutLabel* other) {
    return other != &label && strictly_inside(box_of(*other), label.anchor);
  });
}

bool outside_image(const LayoutLabel& label, const Layout& layout) {
  const Rect box = box_of(label);
  return box.min.x < 0.0 || box.min.y < 0.0 || box.max.x > double(layout.width) ||
         box.max.y > double(layout.height);
}

void measure_leaders(const Layout& layout, const std::vector<const LayoutLabel*>& shown,
                     FrameMetrics& m) {
  const double diagonal = std::hypot(double(layout.width), double(layout.height));
  double sum = 0.0;
  for (const LayoutLabel* label : shown) {
    const auto leader = leader_of(*label);
    if (!leader) continue;
    ++m.leaders;
    const double fraction = diagonal > 0.0 ? glm::distance(leader->a, leader->b) / diagonal : 0.0;
    sum += fraction;
    m.leader_length_max = std::max(m.leader_length_max, fraction);
  }
  m.leader_length_mean = shown.empty() ? 0.0 : sum / double(shown.size());
}

}  // namespace

FrameMetrics frame_metrics(const Layout& layout) {
  const std::vector<const LayoutLabel*> shown = drawn_labels(layout);
  FrameMetrics m;
  m.labels = layout.labels.size();
  for (const LayoutLabel& l : layout.labels) {
    m.shown += l.shown ? 1 : 0;
    m.illegible += l.placed && !l.shown ? 1 : 0;
  }
  m.hidden = m.labels - m.shown;
  count_overlaps(shown, m);
  count_leader_crossings(shown, m);
  for (const LayoutLabel* label : shown) {
    if (leader_through_other_box(*label, shown)) ++m.leaders_through_boxes;
    if (outside_image(*label, layout)) ++m.outside_image;
  }
  for (const LayoutLabel& label : layout.labels) {
    if (anchor_covered(label, shown)) ++m.anchors_covered;
  }
  measure_leaders(layout, shown, m);
  return m;
}

FrameMetrics sum_frame_metrics(const std::vector<FrameMetrics>& frames) {
  FrameMetrics total;
  double leader_length_sum = 0.0;
  for (const FrameMetrics& f : frames) {
    total.labels += f.labels;
    total.shown += f.shown;
    total.hidden += f.hidden;
    total.illegible += f.illegible;
    total.overlaps += f.overlaps;
    total.overlap_area += f.overlap_area;
    total.leader_crossings += f.leader_crossings;
    total.leader_crossings_same_layer += f.leader_crossings_same_layer;
    total.leaders_through_boxes += f.leaders_through_boxes;
    total.anchors_covered += f.anchors_covered;
    total.outside_image += f.outside_image;
    total.leaders += f.leaders;
    leader_length_sum += f.leader_length_mean * double(f.shown);
    total.leader_length_max = std::max(total.leader_length_max, f.leader_length_max);
  }
  total.leader_length_mean = total.shown == 0 ? 0.0 : leader_length_sum / double(total.shown);
  return total;
}

// --- Over a sequence ---

namespace {

glm::dvec2 offset_from_anchor(const LayoutLabel& label) {
  return label.box_origin + 0.5 * label.box_size - label.anchor;
}

double share(size_t count, size_t of) {
  return of == 0 ? 0.0 : double(count) / double(of);
}

// Compares each label of frame `from` with the same id in frame `to`; adds to the counts and
// appends the movements of labels shown in both.
void compare_frames(const Layout& from, const Layout& to, SequenceMetrics& m,
                    std::vector<double>& movements) {
  std::unordered_map<int, const LayoutLabel*> next;
  for (const LayoutLabel& l : to.labels) next.emplace(l.id, &l);
  for (const LayoutLabel& before : from.labels) {
    const auto it = next.find(before.id);
    if (it == next.end()) continue;
    const LayoutLabel& after = *it->second;
    ++m.label_frame_pairs;
    if (before.shown != after.shown) ++m.show_hide_flips;
    if (!(before.placed || before.shown) || !(after.placed || after.shown)) continue;
    ++m.shown_pairs;
    const double movement = glm::distance(offset_from_anchor(after), offset_from_anchor(before));
    movements.push_back(movement);
    if (movement > jump_threshold_px) ++m.jumps;
    if (before.layer != after.layer) ++m.layer_switches;
  }
}

}  // namespace

double nearest_rank_percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = size_t(std::ceil(q * double(values.size())));
  return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

SequenceMetrics sequence_metrics(const std::vector<Layout>& frames) {
  SequenceMetrics m;
  m.frames = frames.size();
  for (const Layout& frame : frames) m.per_frame.push_back(frame_metrics(frame));
  m.total = sum_frame_metrics(m.per_frame);
  std::vector<double> movements;
  for (size_t k = 0; k + 1 < frames.size(); ++k) {
    compare_frames(frames[k], frames[k + 1], m, movements);
  }
  double sum = 0.0;
  for (double movement : movements) sum += movement;
  m.movement_mean = movements.empty() ? 0.0 : sum / double(movements.size());
  m.movement_p95 = nearest_rank_percentile(movements, 0.95);
  m.jump_share = share(m.jumps, m.shown_pairs);
  m.layer_switch_share = share(m.layer_switches, m.shown_pairs);
  m.show_hide_flip_share = share(m.show_hide_flips, m.label_frame_pairs);
  return m;
}

// --- JSON ---

ordered_json to_json(const FrameMetrics& m) {
  return {{"labels", m.labels},
          {"shown", m.shown},
          {"hidden", m.hidden},
          {"illegible", m.illegible},
          {"overlaps", m.overlaps},
          {"overlap_area_px2", m.overlap_area},
          {"leader_crossings", m.leader_crossings},
          {"leader_crossings_same_layer", m.leader_crossings_same_layer},
          {"leaders_through_boxes", m.leaders_through_boxes},
          {"anchors_covered", m.anchors_covered},
          {"outside_image", m.outside_image},
          {"leaders", m.leaders},
          {"leader_length_mean_of_diagonal", m.leader_length_mean},
          {"leader_length_max_of_diagonal", m.leader_length_max}};
}

namespace {

ordered_json temporal_json(const SequenceMetrics& m) {
  return {{"label_frame_pairs", m.label_frame_pairs},
          {"shown_pairs", m.shown_pairs},
          {"movement_mean_px", m.movement_mean},
          {"movement_p95_px", m.movement_p95},
          {"jump_threshold_px", jump_threshold_px},
          {"jumps", m.jumps},
          {"jump_share", m.jump_share},
          {"layer_switches", m.layer_switches},
          {"layer_switch_share", m.layer_switch_share},
          {"show_hide_flips", m.show_hide_flips},
          {"show_hide_flip_share", m.show_hide_flip_share}};
}

}  // namespace

ordered_json to_json(const SequenceMetrics& m) {
  ordered_json per_frame = ordered_json::array();
  for (const FrameMetrics& f : m.per_frame) per_frame.push_back(to_json(f));
  return {{"frames", m.frames},
          {"per_frame", per_frame},
          {"total", to_json(m.total)},
          {"sequence", temporal_json(m)}};
}

}  // namespace strata
