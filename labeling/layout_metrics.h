// Layout quality, measured from the layout files `strata render --layout` writes: overlaps,
// leader crossings, occluded anchors, leader lengths per frame, and movement, jumps, layer
// switches and show/hide flips over a sequence. `strata eval`, the tests, the docs
// (docs/layout-metrics.md) and the benchmarks share these definitions. No GPU.
//
// Pixels, y down. A box is its top-left corner and its size. A label's leader is the segment
// from its anchor to the closest point of its box (as shaders/shared/label_drawing.h draws it);
// a label whose anchor lies in its box (edges included) has none.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <nlohmann/json.hpp>

namespace strata {

struct Rect {
  glm::dvec2 min{0.0};  // top-left corner
  glm::dvec2 max{0.0};  // bottom-right corner
};

struct Segment {
  glm::dvec2 a{0.0};
  glm::dvec2 b{0.0};
};

struct LayoutLabel {
  int id = 0;
  std::string text;
  uint32_t layer = 0;
  glm::dvec2 anchor{0.0};
  glm::dvec2 box_origin{0.0};  // top-left corner
  glm::dvec2 box_size{0.0};
  bool shown = false;   // placed and legible
  bool placed = false;  // drawn (the file's "placed"; without it, "shown")
  double cost = 0.0;    // NaN when the file has null (a non-finite cost)
};

struct Layout {
  std::filesystem::path source;  // for messages
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<LayoutLabel> labels;
};

// A layout file. Every error is "<file>: <field>: <reason>", e.g.
// "a.json: labels[3].box: expected 4 numbers". Required: width, height, labels, and per label
// id (unique), anchor, box (size >= 0) and shown; text, layer and cost are optional (empty, 0,
// 0). Unknown keys are ignored, so files from later versions still read.
Layout read_layout(const std::filesystem::path& path);

// --- Geometry (exact predicates, double precision) ---

Rect box_of(const LayoutLabel& label);

// The point of the closed rectangle nearest to p (p itself when p lies in it).
glm::dvec2 closest_point(const Rect& rect, glm::dvec2 p);

// The leader from the anchor to the closest point of the box; none when the anchor lies in the
// closed box (the label is drawn over its anchor, without a connector).
std::optional<Segment> leader_of(const LayoutLabel& label);

// The area two rectangles share (0 when they only touch).
double intersection_area(const Rect& r, const Rect& s);

// True when the two segments cross at one point inside both: each one's endpoints lie strictly
// on opposite sides of the other's line. Touching (an endpoint on the other segment) and
// collinear segments, overlapping or not, are not crossings: leaders on one line are a
// degenerate case that placement's connector constraints make practically impossible, and
// counting them would make the count depend on rounding.
bool segments_cross(const Segment& s, const Segment& t);

// True when some point of the segment lies strictly inside the rectangle: running along an edge
// or touching a corner is not passing through.
bool segment_enters_interior(const Segment& s, const Rect& rect);

// True when p lies strictly inside the rectangle (on an edge is not inside).
bool strictly_inside(const Rect& rect, glm::dvec2 p);

// --- Per frame ---

// Over the shown labels unless said otherwise. Pair counts count each unordered pair once.
struct FrameMetrics {
  size_t labels = 0;
  size_t shown = 0;      // placed and legible
  size_t hidden = 0;     // not shown: not placed, or placed but illegible
  size_t illegible = 0;  // placed (drawn) but too little of the box is visible
  // The geometry below is over the drawn (placed) labels: an illegible label still draws.
  size_t overlaps = 0;                     // pairs of boxes sharing a positive area
  double overlap_area = 0.0;               // px^2, summed over those pairs
  size_t leader_crossings = 0;             // pairs of leaders that cross (segments_cross)
  size_t leader_crossings_same_layer = 0;  // of those, pairs on the same layer
  // Leaders (each once) entering the interior of another shown label's box
  // (segment_enters_interior).
  size_t leaders_through_boxes = 0;
  // Anchors (each once) of any label, shown or not, strictly inside another shown label's box.
  size_t anchors_covered = 0;
  size_t outside_image = 0;  // boxes not entirely inside [0, width] x [0, height]
  size_t leaders = 0;        // shown labels with a leader
  // Leader length / image diagonal, over the shown labels (no leader = length 0).
  double leader_length_mean = 0.0;
  double leader_length_max = 0.0;
};

FrameMetrics frame_metrics(const Layout& layout);

// Counts and areas summed over frames; leader length mean over every shown label of every frame,
// max over all frames.
FrameMetrics sum_frame_metrics(const std::vector<FrameMetrics>& frames);

// --- Over a sequence ---

inline constexpr double jump_threshold_px = 40.0;

// Labels are matched by id between consecutive frames k and k + 1; a label-frame pair is a label
// present in both. A label's offset is its box centre minus its anchor; its movement from k to
// k + 1 is the length of the offset's change, in pixels (how far the box moved relative to its
// anchor, whatever the anchor did).
struct SequenceMetrics {
  size_t frames = 0;
  std::vector<FrameMetrics> per_frame;
  FrameMetrics total;                 // sum_frame_metrics(per_frame)
  size_t label_frame_pairs = 0;       // present in both frames
  size_t shown_pairs = 0;             // shown in both frames
  double movement_mean = 0.0;         // px, over the shown pairs (0 when there are none)
  double movement_p95 = 0.0;          // px, nearest rank: the ceil(0.95 n)-th smallest
  size_t jumps = 0;                   // shown pairs moving more than jump_threshold_px
  double jump_share = 0.0;            // jumps / shown_pairs
  size_t layer_switches = 0;          // shown pairs whose layer differs
  double layer_switch_share = 0.0;    // layer_switches / shown_pairs
  size_t show_hide_flips = 0;         // label-frame pairs whose shown flag differs
  double show_hide_flip_share = 0.0;  // show_hide_flips / label_frame_pairs
};

SequenceMetrics sequence_metrics(const std::vector<Layout>& frames);

// The nearest-rank percentile (0 < q <= 1) of values: the ceil(q n)-th smallest; 0 when empty.
double nearest_rank_percentile(std::vector<double> values, double q);

nlohmann::ordered_json to_json(const FrameMetrics& metrics);
// {"frames", "per_frame", "total", "sequence"}: the report of `strata eval` for several files.
nlohmann::ordered_json to_json(const SequenceMetrics& metrics);

}  // namespace strata
