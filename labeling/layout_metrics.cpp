#include "labeling/layout_metrics.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "engine/core/error.h"

namespace strata {

using nlohmann::ordered_json;

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

// Drawn (placed, at any opacity) over a title's or legend's box.
bool over_annotation(const LayoutLabel& label, const Layout& layout) {
  if (!label.placed || !(label.opacity > 0.0)) return false;
  return std::any_of(
      layout.annotations.begin(), layout.annotations.end(),
      [&](const LayoutAnnotation& a) { return intersection_area(box_of(label), a.box) > 0.0; });
}

bool opaque(const LayoutLabel& label) {
  return label.opacity >= opaque_opacity;
}

bool apparent(const LayoutLabel& label) {
  return label.opacity > apparent_opacity;
}

// Overlaps and cut boxes of the labels drawn with more than apparent_opacity.
void count_apparent(const Layout& layout, FrameMetrics& m) {
  std::vector<const LayoutLabel*> seen;
  for (const LayoutLabel& l : layout.labels) {
    if (apparent(l)) seen.push_back(&l);
  }
  for (size_t i = 0; i < seen.size(); ++i) {
    if (outside_image(*seen[i], layout)) ++m.cut;
    for (size_t j = i + 1; j < seen.size(); ++j) {
      if (intersection_area(box_of(*seen[i]), box_of(*seen[j])) > 0.0) ++m.apparent_overlaps;
    }
  }
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
  m.opaque = size_t(std::count_if(layout.labels.begin(), layout.labels.end(), opaque));
  count_apparent(layout, m);
  count_overlaps(shown, m);
  count_leader_crossings(shown, m);
  for (const LayoutLabel* label : shown) {
    if (leader_through_other_box(*label, shown)) ++m.leaders_through_boxes;
    if (outside_image(*label, layout)) ++m.outside_image;
  }
  for (const LayoutLabel& label : layout.labels) {
    if (anchor_covered(label, shown)) ++m.anchors_covered;
    if (over_annotation(label, layout)) ++m.over_annotations;
  }
  measure_leaders(layout, shown, m);
  double front_sum = 0.0;
  for (const LayoutLabel& label : layout.labels) {
    if (!label.shown || label.layer == 0 || std::isnan(label.front_alpha)) continue;
    ++m.rear_anchors;
    m.rear_anchors_seen += label.front_alpha <= seen_front_alpha ? 1 : 0;
    front_sum += label.front_alpha;
    m.rear_front_alpha_max = std::max(m.rear_front_alpha_max, label.front_alpha);
  }
  m.rear_front_alpha_mean = m.rear_anchors == 0 ? 0.0 : front_sum / double(m.rear_anchors);
  m.anchors_hidden =
      size_t(std::count_if(layout.labels.begin(), layout.labels.end(), [](const LayoutLabel& l) {
        return l.shown && l.anchor_hidden.value_or(false);
      }));
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
    total.over_annotations += f.over_annotations;
    total.leaders += f.leaders;
    total.opaque += f.opaque;
    total.apparent_overlaps += f.apparent_overlaps;
    total.cut += f.cut;
    total.rear_front_alpha_mean += f.rear_front_alpha_mean * double(f.rear_anchors);  // (a sum)
    total.rear_anchors += f.rear_anchors;
    total.rear_anchors_seen += f.rear_anchors_seen;
    total.rear_front_alpha_max = std::max(total.rear_front_alpha_max, f.rear_front_alpha_max);
    total.anchors_hidden += f.anchors_hidden;
    leader_length_sum += f.leader_length_mean * double(f.shown + f.illegible);  // (drawn)
    total.leader_length_max = std::max(total.leader_length_max, f.leader_length_max);
  }
  const size_t drawn = total.shown + total.illegible;
  total.leader_length_mean = drawn == 0 ? 0.0 : leader_length_sum / double(drawn);
  total.rear_front_alpha_mean =
      total.rear_anchors == 0 ? 0.0 : total.rear_front_alpha_mean / double(total.rear_anchors);
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

// What the comparisons of consecutive frames collect besides the counts.
struct Movements {
  std::vector<double> px;                // shown pairs: the offset's change
  std::vector<double> width_per_second;  // opaque pairs: of the width, per second
  double label_seconds = 0.0;            // label-frame pairs: frame k + 1's seconds summed
};

// The opaque-state measures of one label-frame pair: flips, and for a label opaque in both
// frames its motion relative to the image.
void compare_opaque(const LayoutLabel& before, const LayoutLabel& after, const Layout& to,
                    SequenceMetrics& m, Movements& movements) {
  if (to.seconds) movements.label_seconds += *to.seconds;
  if (opaque(before) != opaque(after)) ++m.opaque_flips;
  if (!opaque(before) || !opaque(after)) return;
  ++m.opaque_pairs;
  const double of_width =
      glm::distance(offset_from_anchor(after), offset_from_anchor(before)) / double(to.width);
  if (of_width > jump_threshold_of_width) ++m.opaque_jumps;
  if (to.seconds) movements.width_per_second.push_back(of_width / *to.seconds);
}

// Compares each label of frame `from` with the same id in frame `to`; adds to the counts and
// the movements.
void compare_frames(const Layout& from, const Layout& to, SequenceMetrics& m,
                    Movements& movements) {
  std::unordered_map<int, const LayoutLabel*> next;
  for (const LayoutLabel& l : to.labels) next.emplace(l.id, &l);
  for (const LayoutLabel& before : from.labels) {
    const auto it = next.find(before.id);
    if (it == next.end()) continue;
    const LayoutLabel& after = *it->second;
    ++m.label_frame_pairs;
    if (before.shown != after.shown) ++m.show_hide_flips;
    compare_opaque(before, after, to, m, movements);
    if (!(before.placed || before.shown) || !(after.placed || after.shown)) continue;
    ++m.shown_pairs;
    const double movement = glm::distance(offset_from_anchor(after), offset_from_anchor(before));
    movements.px.push_back(movement);
    if (movement > jump_threshold_px) ++m.jumps;
    if (before.layer != after.layer) ++m.layer_switches;
  }
}

double mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double value : values) sum += value;
  return values.empty() ? 0.0 : sum / double(values.size());
}

// The sequence's duration: frame 1 .. N - 1's time steps; none for a single frame or when one
// of them has none.
std::optional<double> duration(const std::vector<Layout>& frames) {
  if (frames.size() < 2) return std::nullopt;
  double sum = 0.0;
  for (size_t k = 1; k < frames.size(); ++k) {
    if (!frames[k].seconds) return std::nullopt;
    sum += *frames[k].seconds;
  }
  return sum;
}

std::string extent_text(const Layout& layout) {
  return std::to_string(layout.width) + "x" + std::to_string(layout.height);
}

std::vector<FrameMetrics> still_metrics(const std::vector<Layout>& frames,
                                        const std::vector<Layout>& stills) {
  if (stills.empty()) return {};
  if (stills.size() != frames.size()) {
    throw Error("stills: " + std::to_string(stills.size()) + " layouts for " +
                std::to_string(frames.size()) + " frames");
  }
  std::vector<FrameMetrics> out;
  for (size_t k = 0; k < frames.size(); ++k) {
    if (stills[k].width != frames[k].width || stills[k].height != frames[k].height) {
      throw Error(stills[k].source.string() + ": a still of " + extent_text(stills[k]) +
                  " for a frame of " + extent_text(frames[k]) + " (" + frames[k].source.string() +
                  ")");
    }
    out.push_back(frame_metrics(stills[k]));
  }
  return out;
}

}  // namespace

double nearest_rank_percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = size_t(std::ceil(q * double(values.size())));
  return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

SequenceMetrics sequence_metrics(const std::vector<Layout>& frames,
                                 const std::vector<Layout>& stills) {
  SequenceMetrics m;
  m.frames = frames.size();
  m.stills = still_metrics(frames, stills);
  m.stills_total = sum_frame_metrics(m.stills);
  for (const Layout& frame : frames) m.per_frame.push_back(frame_metrics(frame));
  m.total = sum_frame_metrics(m.per_frame);
  Movements movements;
  for (size_t k = 0; k + 1 < frames.size(); ++k) {
    compare_frames(frames[k], frames[k + 1], m, movements);
  }
  m.movement_mean = mean(movements.px);
  m.movement_p95 = nearest_rank_percentile(movements.px, 0.95);
  m.jump_share = share(m.jumps, m.shown_pairs);
  m.layer_switch_share = share(m.layer_switches, m.shown_pairs);
  m.show_hide_flip_share = share(m.show_hide_flips, m.label_frame_pairs);
  m.seconds = duration(frames);
  if (m.seconds) {
    m.motion_mean = mean(movements.width_per_second);
    m.motion_p95 = nearest_rank_percentile(movements.width_per_second, 0.95);
    m.opaque_flips_per_label_per_second =
        movements.label_seconds > 0.0 ? double(m.opaque_flips) / movements.label_seconds : 0.0;
  }
  m.ranges = active_range_metrics(frames, stills);
  return m;
}

// --- JSON ---

namespace {

template <typename Number>
ordered_json optional_number(std::optional<Number> value) {
  return value ? ordered_json(*value) : ordered_json();
}

std::optional<double> ratio(size_t count, size_t of) {
  return of == 0 ? std::nullopt : std::optional(double(count) / double(of));
}

}  // namespace

ordered_json to_json(const FrameMetrics& m, const FrameMetrics* still) {
  ordered_json out = {{"labels", m.labels},
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
                      {"over_annotations", m.over_annotations},
                      {"leaders", m.leaders},
                      {"leader_length_mean_of_diagonal", m.leader_length_mean},
                      {"leader_length_max_of_diagonal", m.leader_length_max},
                      {"opaque", m.opaque},
                      {"apparent_overlaps", m.apparent_overlaps},
                      {"cut", m.cut},
                      {"rear_anchors", m.rear_anchors},
                      {"rear_anchors_seen", m.rear_anchors_seen},
                      {"rear_front_alpha_mean", m.rear_front_alpha_mean},
                      {"rear_front_alpha_max", m.rear_front_alpha_max},
                      {"anchors_hidden", m.anchors_hidden}};
  if (still) {
    out["still_opaque"] = still->opaque;
    out["opaque_of_still"] = optional_number(ratio(m.opaque, still->opaque));
    out["still_leader_crossings"] = still->leader_crossings;
  }
  return out;
}

namespace {

ordered_json temporal_json(const SequenceMetrics& m) {
  return {
      {"label_frame_pairs", m.label_frame_pairs},
      {"shown_pairs", m.shown_pairs},
      {"movement_mean_px", m.movement_mean},
      {"movement_p95_px", m.movement_p95},
      {"jump_threshold_px", jump_threshold_px},
      {"jumps", m.jumps},
      {"jump_share", m.jump_share},
      {"layer_switches", m.layer_switches},
      {"layer_switch_share", m.layer_switch_share},
      {"show_hide_flips", m.show_hide_flips},
      {"show_hide_flip_share", m.show_hide_flip_share},
      {"seconds", optional_number(m.seconds)},
      {"opaque_pairs", m.opaque_pairs},
      {"motion_mean_of_width_per_second", optional_number(m.motion_mean)},
      {"motion_p95_of_width_per_second", optional_number(m.motion_p95)},
      {"jump_threshold_of_width", jump_threshold_of_width},
      {"opaque_jumps", m.opaque_jumps},
      {"opaque_flips", m.opaque_flips},
      {"opaque_flips_per_label_per_second", optional_number(m.opaque_flips_per_label_per_second)}};
}

void add_ranges_json(const ActiveRangeMetrics& r, bool stills, ordered_json& out) {
  out["readable_label_frames"] = r.readable_label_frames;
  out["readable_label_seconds"] = optional_number(r.readable_label_seconds);
  if (stills) {
    out["still_readable_label_seconds"] = optional_number(r.still_readable_label_seconds);
    out["readable_of_stills"] = optional_number(r.readable_of_stills);
    out["bound_label_seconds"] = optional_number(r.bound_label_seconds);
    out["readable_of_bound"] = optional_number(r.readable_of_bound);
  }
  out["visible_stretches"] = r.visible_stretches;
  out["active_ranges"] = r.active_ranges;
  out["extra_ranges"] = r.extra_ranges;
  out["extra_ranges_per_label_per_second"] = optional_number(r.extra_ranges_per_label_per_second);
  out["short_ranges"] = optional_number(r.short_ranges);
  out["short_ranges_inside"] = optional_number(r.short_ranges_inside);
}

}  // namespace

ordered_json to_json(const SequenceMetrics& m, bool with_per_frame) {
  const bool stills = !m.stills.empty();
  ordered_json out = {{"frames", m.frames}};
  if (with_per_frame) {
    ordered_json per_frame = ordered_json::array();
    for (size_t k = 0; k < m.per_frame.size(); ++k) {
      per_frame.push_back(to_json(m.per_frame[k], stills ? &m.stills[k] : nullptr));
    }
    out["per_frame"] = per_frame;
  }
  out["total"] = to_json(m.total, stills ? &m.stills_total : nullptr);
  out["sequence"] = temporal_json(m);
  add_ranges_json(m.ranges, stills, out["sequence"]);
  return out;
}

}  // namespace strata
