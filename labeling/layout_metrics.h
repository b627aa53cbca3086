// Layout quality, measured from the layout files `strata render --layout` and `strata video
// --layout-dir` write: overlaps, cut boxes, leader crossings, occluded anchors, leader lengths
// per frame, and movement, jumps, layer switches, flips and active ranges over a sequence,
// optionally against stills of the same views. `strata eval`, `strata video --report`, the
// tests, the docs (docs/layout-metrics.md) and the benchmarks share these definitions. No GPU.
//
// Pixels, y down. A box is its top-left corner and its size. A label's leader is the segment
// from its anchor to the closest point of its box (as shaders/shared/label_drawing.h draws it);
// a label whose anchor lies in its box (edges included) has none.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
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
  // The drawn opacity, 0..1 (the file's "opacity"; without it, 1 when placed, else 0).
  double opacity = 0.0;
  // The placement's box this frame, where the label is heading (the file's "target"; without
  // it, the box); none where the file has null (the placement did not place the label).
  std::optional<Rect> target;
  // The alpha of the layers in front of the label's own at its anchor (the file's "front_alpha";
  // NaN without it or with null).
  double front_alpha = std::numeric_limits<double>::quiet_NaN();
  // Whether the picture hides the anchor (the file's "anchor_hidden"; none without it or with
  // null).
  std::optional<bool> anchor_hidden;
};

// A box drawn over the picture that is not a label's: a title, a legend (the file's
// "annotations"; labels keep off them).
struct LayoutAnnotation {
  std::string name;
  Rect box;
};

struct Layout {
  std::filesystem::path source;  // for messages
  uint32_t width = 0;
  uint32_t height = 0;
  // The frame's time step (the file's "seconds"); none for a still or an older file.
  std::optional<double> seconds;
  std::vector<LayoutLabel> labels;
  std::vector<LayoutAnnotation> annotations;
};

// A layout file. Every error is "<file>: <field>: <reason>", e.g.
// "a.json: labels[3].box: expected 4 numbers". Required: width, height, labels, and per label
// id (unique), anchor, box (size >= 0) and shown; text, layer, cost, placed, opacity, target,
// front_alpha, anchor_hidden and the top level's seconds and annotations (each a name and a box)
// are optional (defaults above). Unknown
// keys are ignored, so files from later versions still read.
Layout read_layout(const std::filesystem::path& path);
// The same from JSON already parsed (`strata video --report` reads the layouts it writes);
// `source` names it in errors.
Layout parse_layout(const nlohmann::json& root, const std::filesystem::path& source);

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
  // Drawn labels (placed, opacity > 0) whose box shares a positive area with an annotation's box
  // (a title, a legend): each label once.
  size_t over_annotations = 0;
  size_t leaders = 0;  // shown labels with a leader
  // Leader length / image diagonal, over the shown labels (no leader = length 0).
  double leader_length_mean = 0.0;
  double leader_length_max = 0.0;
  // By the drawn opacity (a fading label is drawn, but not read): issue 33's measures.
  size_t opaque = 0;             // labels with opacity >= opaque_opacity ("shown" in motion)
  size_t apparent_overlaps = 0;  // pairs, both opacity > apparent_opacity, interiors intersecting
  size_t cut = 0;                // opacity > apparent_opacity, box not wholly inside the image
  // Shown labels on a rear layer whose front alpha was measured: how much hides their anchors
  // (ghosting's measure), and how many of those anchors the front hides little
  // (front_alpha <= seen_front_alpha).
  size_t rear_anchors = 0;
  size_t rear_anchors_seen = 0;
  double rear_front_alpha_mean = 0.0;
  double rear_front_alpha_max = 0.0;
  // Shown labels whose anchor the picture hides (anchor_hidden): drawn with a dashed leader to a
  // hollow mark.
  size_t anchors_hidden = 0;
};

inline constexpr double seen_front_alpha = 0.3;

FrameMetrics frame_metrics(const Layout& layout);

// Counts and areas summed over frames; leader length mean over every shown label of every frame,
// max over all frames.
FrameMetrics sum_frame_metrics(const std::vector<FrameMetrics>& frames);

// --- Over a sequence ---

inline constexpr double jump_threshold_px = 40.0;
// A label is opaque (shown, for the viewer) from this opacity, apparent above this one.
inline constexpr double opaque_opacity = 0.5;
inline constexpr double apparent_opacity = 0.1;
// An opaque label jumps when its offset changes by more than this share of the image width in
// one frame.
inline constexpr double jump_threshold_of_width = 0.04;

// How steadily labels stay readable (issue 50; computed in active_ranges.cpp). A label is
// readable in a frame where it is shown with opacity >= opaque_opacity; its active ranges are its
// runs of readable frames; a visible stretch is a run of frames in which the label is in the file
// and its anchor lies in the closed image rectangle (or the label is readable).

// A range is short below this many seconds, less a tolerance for the rounding of the time steps.
inline constexpr double short_range_seconds = 1.0;

// Each frame k >= 1 weighs its `seconds` and frame 0 nothing, as the sequence's duration does;
// the figures in seconds are none when the sequence has no duration (one frame, or a frame from
// 1 on without seconds).
struct ActiveRangeMetrics {
  size_t readable_label_frames = 0;  // labels shown with opacity >= opaque_opacity, over frames
  std::optional<double> readable_label_seconds;
  // With stills: theirs, weighed by the sequence's frames, and ours / theirs (none when 0).
  std::optional<double> still_readable_label_seconds;
  std::optional<double> readable_of_stills;
  // With stills: the most readable label-seconds with one range per stretch, none short inside,
  // each label where the stills put it (best_consistent_seconds in video_plan.h), and ours / it.
  std::optional<double> bound_label_seconds;
  std::optional<double> readable_of_bound;
  size_t visible_stretches = 0;  // runs of frames in which a label's anchor is in view
  size_t active_ranges = 0;      // runs of frames in which a label is readable
  size_t extra_ranges = 0;       // ranges beyond the first of their stretch
  // extra_ranges / the label-seconds (each label-frame pair counts frame k + 1's seconds).
  std::optional<double> extra_ranges_per_label_per_second;
  std::optional<size_t> short_ranges;         // shorter than short_range_seconds
  std::optional<size_t> short_ranges_inside;  // of those, touching neither end of the sequence
};

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

  // By the drawn opacity, over opaque pairs (opaque in both frames); per second with the frames'
  // time steps (frame k + 1's seconds for the pair k, k + 1): none when a frame lacks one.
  std::optional<double> seconds;  // the sum of the time steps of frames 1 .. N - 1
  size_t opaque_pairs = 0;
  // The offset's change / frame k + 1's width / its seconds, over the opaque pairs (0 when none).
  std::optional<double> motion_mean;
  std::optional<double> motion_p95;  // nearest rank
  size_t opaque_jumps = 0;           // opaque pairs moving more than jump_threshold_of_width
  size_t opaque_flips = 0;           // label-frame pairs whose opaque state differs
  // opaque_flips / the label-seconds: each label-frame pair counts frame k + 1's seconds.
  std::optional<double> opaque_flips_per_label_per_second;

  // Stills of the same views, frame by frame (empty: none given).
  std::vector<FrameMetrics> stills;
  FrameMetrics stills_total;  // sum_frame_metrics(stills)

  ActiveRangeMetrics ranges;  // active_range_metrics(frames, stills)
};

// `stills`: empty, or the layouts of still placements of the same cameras, one per frame, each
// the size of its frame (an Error otherwise).
SequenceMetrics sequence_metrics(const std::vector<Layout>& frames,
                                 const std::vector<Layout>& stills = {});

// A label's state in one frame of a sequence.
enum class FrameState : char {
  absent,       // not in the frame's file
  out_of_view,  // its anchor outside the image
  visible,      // its anchor in view, the label not readable
  readable,
};
bool readable(const LayoutLabel& label);
// In view: the anchor in the closed image rectangle, or the label readable.
FrameState frame_state(const LayoutLabel& label, const Layout& frame);
// What each frame weighs in seconds: its time step, frame 0 nothing.
std::vector<double> frame_weights(const std::vector<Layout>& frames);

// `stills`: empty, or one per frame (as for sequence_metrics, which checks them).
ActiveRangeMetrics active_range_metrics(const std::vector<Layout>& frames,
                                        const std::vector<Layout>& stills = {});

// The nearest-rank percentile (0 < q <= 1) of values: the ceil(q n)-th smallest; 0 when empty.
double nearest_rank_percentile(std::vector<double> values, double q);

// `still`: the metrics of a still of the same view, or none: adds the still's opaque labels and
// leader crossings and opaque / the still's opaque.
nlohmann::ordered_json to_json(const FrameMetrics& metrics, const FrameMetrics* still = nullptr);
// {"frames", "per_frame", "total", "sequence"}: the report of `strata eval` for several files;
// without per_frame, the summary `strata video --report` prints.
nlohmann::ordered_json to_json(const SequenceMetrics& metrics, bool with_per_frame = true);

}  // namespace strata
