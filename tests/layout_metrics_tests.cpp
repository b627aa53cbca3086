// The layout-quality metrics of `strata eval` on hand-made layouts whose answers are known.
#include <doctest/doctest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "labeling/layout_metrics.h"
#include "labeling/video_plan.h"
#include "test_files.h"

namespace strata {
namespace {

// A label with its box's top-left corner and size; shown (opacity 1) on layer 0 unless said
// otherwise.
LayoutLabel label(int id, glm::dvec2 anchor, glm::dvec2 origin, glm::dvec2 size, bool shown = true,
                  uint32_t layer = 0) {
  return {.id = id,
          .layer = layer,
          .anchor = anchor,
          .box_origin = origin,
          .box_size = size,
          .shown = shown,
          .opacity = shown ? 1.0 : 0.0};
}

// A label drawn (placed) with this opacity, as the forces fade it.
LayoutLabel fading(LayoutLabel l, double opacity) {
  l.placed = opacity > 0.0;
  l.shown = l.placed;
  l.opacity = opacity;
  return l;
}

// A label drawn over its anchor (no leader): the box centred on the anchor.
LayoutLabel internal_label(int id, glm::dvec2 origin, glm::dvec2 size, bool shown = true) {
  return label(id, origin + 0.5 * size, origin, size, shown);
}

Layout layout(uint32_t width, uint32_t height, std::vector<LayoutLabel> labels) {
  Layout l;
  l.width = width;
  l.height = height;
  l.labels = std::move(labels);
  return l;
}

Layout timed(Layout l, double seconds) {
  l.seconds = seconds;
  return l;
}

Segment segment(glm::dvec2 a, glm::dvec2 b) {
  return {a, b};
}
Rect rect(glm::dvec2 min, glm::dvec2 max) {
  return {min, max};
}

// A label whose box centre sits at anchor + offset.
LayoutLabel offset_label(int id, glm::dvec2 anchor, glm::dvec2 offset, bool shown = true,
                         uint32_t layer = 0) {
  const glm::dvec2 size{20.0, 10.0};
  return label(id, anchor, anchor + offset - 0.5 * size, size, shown, layer);
}

std::string layout_error(const std::string& name, const std::string& text) {
  const auto folder = test::fresh_folder("cpu", "layout_metrics_" + name);
  const auto path = test::write_file(folder / "layout.json", text);
  return test::error_of([&] { read_layout(path); });
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("segments_cross_only_at_a_point_inside_both") {
    CHECK(segments_cross(segment({0, 0}, {10, 10}), segment({0, 10}, {10, 0})));
    // A shared endpoint, an endpoint on the other segment (T), collinear overlap, parallel.
    CHECK_FALSE(segments_cross(segment({0, 0}, {10, 10}), segment({10, 10}, {20, 0})));
    CHECK_FALSE(segments_cross(segment({0, 0}, {10, 10}), segment({5, 5}, {5, 20})));
    CHECK_FALSE(segments_cross(segment({0, 0}, {10, 0}), segment({5, 0}, {15, 0})));
    CHECK_FALSE(segments_cross(segment({0, 0}, {10, 0}), segment({0, 1}, {10, 1})));
    // The lines cross, the segments do not.
    CHECK_FALSE(segments_cross(segment({0, 0}, {4, 4}), segment({0, 10}, {10, 0})));
  }

  TEST_CASE("a_segment_enters_a_rectangle_only_through_its_interior") {
    const Rect r = rect({0, 0}, {10, 10});
    CHECK(segment_enters_interior(segment({-5, 5}, {15, 5}), r));
    CHECK(segment_enters_interior(segment({5, 5}, {6, 6}), r));            // wholly inside
    CHECK(segment_enters_interior(segment({-5, 5}, {1, 5}), r));           // ends inside
    CHECK_FALSE(segment_enters_interior(segment({-5, 0}, {15, 0}), r));    // along an edge
    CHECK_FALSE(segment_enters_interior(segment({-5, 5}, {0, 5}), r));     // ends on an edge
    CHECK_FALSE(segment_enters_interior(segment({-1, 1}, {1, -1}), r));    // touches a corner
    CHECK_FALSE(segment_enters_interior(segment({-5, 20}, {15, 20}), r));  // misses
    CHECK_FALSE(segment_enters_interior(segment({11, -5}, {20, 5}), r));
  }

  TEST_CASE("the_leader_ends_at_the_closest_point_of_the_box") {
    const Rect r = rect({10, 20}, {30, 30});
    CHECK(closest_point(r, {0, 0}) == glm::dvec2(10, 20));
    CHECK(closest_point(r, {20, 50}) == glm::dvec2(20, 30));
    CHECK(closest_point(r, {15, 25}) == glm::dvec2(15, 25));
    const auto leader = leader_of(label(1, {20, 50}, {10, 20}, {20, 10}));
    REQUIRE(leader);
    CHECK(leader->a == glm::dvec2(20, 50));
    CHECK(leader->b == glm::dvec2(20, 30));
    // An anchor inside the box or on its edge has no leader.
    CHECK_FALSE(leader_of(label(1, {15, 25}, {10, 20}, {20, 10})));
    CHECK_FALSE(leader_of(label(1, {30, 25}, {10, 20}, {20, 10})));
  }

  TEST_CASE("overlapping_boxes_count_one_pair_with_the_exact_shared_area") {
    const FrameMetrics m = frame_metrics(
        layout(100, 100,
               {internal_label(1, {0, 0}, {10, 10}), internal_label(2, {6, 4}, {10, 10}),
                // Touches box 1 at a corner only.
                internal_label(3, {-5, 10}, {5, 5}),
                // Hidden: never overlaps.
                internal_label(4, {2, 2}, {5, 5}, false)}));
    CHECK(m.labels == 4);
    CHECK(m.shown == 3);
    CHECK(m.hidden == 1);
    CHECK(m.overlaps == 1);
    CHECK(m.overlap_area == 24.0);  // 4 x 6
    CHECK(intersection_area(rect({0, 0}, {10, 10}), rect({10, 0}, {20, 10})) == 0.0);
  }

  TEST_CASE("two_crossing_leaders_are_one_crossing_split_by_layer") {
    // (10,10) to (50,50) and (50,10) to (10,50) cross at (30,30).
    const auto frame = [](uint32_t second_layer) {
      return layout(100, 100,
                    {label(1, {10, 10}, {50, 50}, {10, 10}, true, 0),
                     label(2, {50, 10}, {0, 50}, {10, 10}, true, second_layer)});
    };
    const FrameMetrics apart = frame_metrics(frame(1));
    CHECK(apart.leader_crossings == 1);
    CHECK(apart.leader_crossings_same_layer == 0);
    CHECK(apart.leaders_through_boxes == 0);
    const FrameMetrics together = frame_metrics(frame(0));
    CHECK(together.leader_crossings == 1);
    CHECK(together.leader_crossings_same_layer == 1);
  }

  TEST_CASE("leaders_touching_at_an_endpoint_do_not_cross") {
    // Label 2's anchor lies on label 1's leader; label 3's leader starts where label 1's does.
    const FrameMetrics m = frame_metrics(
        layout(100, 100,
               {label(1, {10, 10}, {50, 50}, {10, 10}), label(2, {30, 30}, {30, 60}, {10, 10}),
                label(3, {10, 10}, {-20, 5}, {10, 10}),
                // Hidden: its leader would cross label 1's.
                label(4, {50, 10}, {0, 50}, {10, 10}, false)}));
    CHECK(m.leaders == 3);
    CHECK(m.leader_crossings == 0);
  }

  TEST_CASE("a_leader_through_a_third_label_box_counts_and_one_along_an_edge_does_not") {
    const FrameMetrics m = frame_metrics(
        layout(100, 100,
               {label(1, {10, 50}, {80, 45}, {10, 10}),    // leader (10,50)-(80,50)
                internal_label(2, {40, 40}, {10, 20}),     // the leader crosses it
                internal_label(3, {20, 50}, {10, 10}),     // the leader runs on its top
                internal_label(4, {60, 20}, {10, 30})}));  // its bottom touches y = 50
    CHECK(m.leaders_through_boxes == 1);
    CHECK(m.overlaps == 0);
  }

  TEST_CASE("an_anchor_strictly_inside_another_shown_box_is_covered") {
    const FrameMetrics m = frame_metrics(
        layout(100, 100,
               {internal_label(1, {0, 0}, {20, 20}),            // its own anchor: not covered
                label(2, {10, 10}, {60, 60}, {10, 10}, false),  // hidden, anchor under box 1
                label(3, {5, 5}, {50, 0}, {10, 10}),            // shown, anchor under box 1
                label(4, {20, 10}, {60, 20}, {10, 10}),         // anchor on box 1's edge
                label(5, {80, 80}, {30, 30}, {30, 30}, false),  // hidden box: covers nothing
                internal_label(6, {40, 40}, {10, 10})}));
    CHECK(m.anchors_covered == 2);
    // Label 3's leader starts inside box 1.
    CHECK(m.leaders_through_boxes == 1);
  }

  TEST_CASE("a_label_partly_outside_the_image_counts_and_one_touching_its_corner_does_not") {
    const FrameMetrics m = frame_metrics(layout(
        100, 80,
        {internal_label(1, {-5, 10}, {20, 10}), internal_label(2, {90, 70}, {10, 10}),
         internal_label(3, {50, 75}, {10, 10}), internal_label(4, {-50, -50}, {10, 10}, false)}));
    CHECK(m.outside_image == 2);
  }

  TEST_CASE("leader_lengths_are_fractions_of_the_image_diagonal") {
    // Diagonal 500; leaders 50 and 150 long, and a label without one.
    const FrameMetrics m = frame_metrics(layout(
        300, 400,
        {label(1, {0, 0}, {30, 40}, {10, 10}), label(2, {100, 100}, {100, 250}, {10, 10}),
         internal_label(3, {200, 200}, {10, 10}), label(4, {0, 0}, {300, 300}, {10, 10}, false)}));
    CHECK(m.leaders == 2);
    CHECK(m.leader_length_max == doctest::Approx(0.3).epsilon(1e-12));
    CHECK(m.leader_length_mean == doctest::Approx(0.4 / 3.0).epsilon(1e-12));
  }

  TEST_CASE("the_nearest_rank_percentile_is_the_ceil_qn_th_smallest") {
    std::vector<double> twenty;
    for (int i = 20; i >= 1; --i) twenty.push_back(i);
    CHECK(nearest_rank_percentile(twenty, 0.95) == 19.0);
    CHECK(nearest_rank_percentile({3, 1, 2}, 0.95) == 3.0);
    CHECK(nearest_rank_percentile({0, 50, 3, 5, 40}, 0.5) == 5.0);
    CHECK(nearest_rank_percentile({}, 0.95) == 0.0);
  }

  TEST_CASE("a_three_frame_sequence_has_its_known_movements_jump_switch_and_flip") {
    // Label 1 moves 3 then 5 px against its anchor; label 2 jumps 50 px, then switches layer;
    // label 3 is hidden after frame 0; label 4's anchor moves 100 px and its box moves exactly
    // 40 px against it (no jump: the threshold is strict); label 5 appears in frame 2 only.
    const Layout f0 =
        layout(200, 200,
               {offset_label(1, {10, 10}, {20, 0}), offset_label(2, {50, 50}, {0, 30}),
                offset_label(3, {90, 90}, {0, 20}), offset_label(4, {20, 150}, {0, 0})});
    const Layout f1 =
        layout(200, 200,
               {offset_label(1, {10, 10}, {20, 3}), offset_label(2, {50, 50}, {30, 70}),
                offset_label(3, {90, 90}, {0, 20}, false), offset_label(4, {120, 150}, {24, 32})});
    const Layout f2 =
        layout(200, 200,
               {offset_label(1, {10, 10}, {23, 7}), offset_label(2, {50, 50}, {30, 70}, true, 1),
                offset_label(3, {90, 90}, {0, 20}, false), offset_label(5, {100, 100}, {0, 20})});
    const SequenceMetrics m = sequence_metrics({f0, f1, f2});
    CHECK(m.frames == 3);
    CHECK(m.label_frame_pairs == 7);  // 4 from frame 0 to 1, 3 from 1 to 2
    CHECK(m.shown_pairs == 5);
    // Movements 3, 50, 40, 5, 0.
    CHECK(m.movement_mean == doctest::Approx(98.0 / 5.0).epsilon(1e-12));
    CHECK(m.movement_p95 == doctest::Approx(50.0).epsilon(1e-12));
    CHECK(m.jumps == 1);
    CHECK(m.jump_share == doctest::Approx(0.2));
    CHECK(m.layer_switches == 1);
    CHECK(m.layer_switch_share == doctest::Approx(0.2));
    CHECK(m.show_hide_flips == 1);
    CHECK(m.show_hide_flip_share == doctest::Approx(1.0 / 7.0));
    REQUIRE(m.per_frame.size() == 3);
    CHECK(m.per_frame[1].hidden == 1);
    CHECK(m.total.labels == 12);
    CHECK(m.total.shown == 10);
    CHECK(m.total.hidden == 2);
  }

  TEST_CASE("summed_frame_metrics_pool_leader_lengths_over_every_drawn_label") {
    FrameMetrics a, b;
    a.shown = 1;
    a.leader_length_mean = 0.4;
    a.leader_length_max = 0.4;
    a.overlaps = 2;
    a.overlap_area = 10.0;
    b.shown = 2;
    b.illegible = 1;  // drawn: its leader counts
    b.leader_length_mean = 0.2;
    b.leader_length_max = 0.5;
    b.overlaps = 1;
    b.overlap_area = 2.5;
    a.opaque = 1;
    b.opaque = 2;
    b.apparent_overlaps = 1;
    a.cut = 1;
    const FrameMetrics total = sum_frame_metrics({a, b});
    CHECK(total.shown == 3);
    CHECK(total.opaque == 3);
    CHECK(total.apparent_overlaps == 1);
    CHECK(total.cut == 1);
    CHECK(total.overlaps == 3);
    CHECK(total.overlap_area == 12.5);
    CHECK(total.leader_length_mean == doctest::Approx(0.25));
    CHECK(total.leader_length_max == 0.5);
  }

  TEST_CASE("labels_are_opaque_from_half_opacity") {
    const FrameMetrics m = frame_metrics(layout(100, 100,
                                                {fading(internal_label(1, {0, 0}, {10, 10}), 0.5),
                                                 fading(internal_label(2, {20, 0}, {10, 10}), 0.49),
                                                 fading(internal_label(3, {40, 0}, {10, 10}), 1.0),
                                                 internal_label(4, {60, 0}, {10, 10}, false)}));
    CHECK(m.opaque == 2);
    CHECK(m.shown == 3);  // (placed, whatever the opacity)
  }

  TEST_CASE("a_box_cut_by_the_image_edge_counts_above_a_tenth_of_opacity") {
    const FrameMetrics m =
        frame_metrics(layout(100, 80,
                             {internal_label(1, {-5, 10}, {20, 10}),                // cut, opaque
                              fading(internal_label(2, {95, 30}, {10, 10}), 0.11),  // cut, faint
                              fading(internal_label(3, {50, 75}, {10, 10}), 0.1),  // cut, too faint
                              internal_label(4, {90, 70}, {10, 10}),  // touches the corner
                              internal_label(5, {-50, -50}, {10, 10}, false)}));  // hidden
    CHECK(m.cut == 2);
    CHECK(m.outside_image == 3);  // (every drawn box)
  }

  TEST_CASE("fading_boxes_overlap_only_both_above_a_tenth_of_opacity") {
    const FrameMetrics m = frame_metrics(layout(
        100, 100,
        {internal_label(1, {0, 0}, {20, 20}),
         fading(internal_label(2, {10, 10}, {20, 20}), 0.1),  // under 1: too faint
         fading(internal_label(3, {15, 5}, {20, 10}), 0.2),   // over 1 (and 2)
         internal_label(4, {60, 60}, {10, 10}), internal_label(5, {70, 60}, {10, 10}),  // touches 4
         fading(internal_label(6, {62, 62}, {5, 5}), 0.0)}));  // in 4, not drawn
    CHECK(m.apparent_overlaps == 1);
    CHECK(m.overlaps == 3);  // (1-2, 1-3, 2-3: every drawn pair)
  }

  TEST_CASE("motion_is_a_share_of_the_image_width_per_second_and_a_jump_passes_4_percent") {
    // 200 px wide, 0.1 s a frame. Label 1 moves 4 px against its anchor (2 % of the width:
    // 0.2 a second), label 2 10 px (5 %: a jump), label 3 exactly 8 px (4 %: no jump), label 4
    // 100 px while fading (not opaque in frame 1: not counted), label 5 follows its anchor.
    const Layout f0 =
        timed(layout(200, 100,
                     {offset_label(1, {10, 10}, {20, 0}), offset_label(2, {50, 50}, {0, 30}),
                      offset_label(3, {90, 90}, {0, 20}), offset_label(4, {20, 50}, {0, 0}),
                      offset_label(5, {150, 50}, {0, 20})}),
              0.1);
    const Layout f1 =
        timed(layout(200, 100,
                     {offset_label(1, {10, 10}, {20, 4}), offset_label(2, {50, 50}, {6, 38}),
                      offset_label(3, {90, 90}, {8, 20}),
                      fading(offset_label(4, {20, 50}, {100, 0}), 0.4),
                      offset_label(5, {170, 50}, {0, 20})}),
              0.1);
    const SequenceMetrics m = sequence_metrics({f0, f1});
    CHECK(m.opaque_pairs == 4);
    REQUIRE(m.seconds);
    CHECK(*m.seconds == doctest::Approx(0.1));
    REQUIRE(m.motion_mean);
    CHECK(*m.motion_mean == doctest::Approx((0.2 + 0.5 + 0.4 + 0.0) / 4.0).epsilon(1e-12));
    CHECK(*m.motion_p95 == doctest::Approx(0.5).epsilon(1e-12));
    CHECK(m.opaque_jumps == 1);
    CHECK(m.opaque_flips == 1);  // label 4
    CHECK(m.jumps == 1);         // (40 px: label 4 only)
  }

  TEST_CASE("flips_are_changes_of_the_opaque_state_per_label_and_second") {
    // Three frames, 0.5 s apart: label 1 goes 1, 0.4, 0.6 (two flips), label 2 0.5, 0.5, 1
    // (none), label 3 is there in frame 0 only. 4 label-frame pairs of 0.5 s: 2 label-seconds.
    const auto frame = [](double first, double second, bool third) {
      std::vector<LayoutLabel> labels = {fading(offset_label(1, {10, 10}, {20, 0}), first),
                                         fading(offset_label(2, {50, 50}, {0, 30}), second)};
      if (third) labels.push_back(offset_label(3, {90, 90}, {0, 20}));
      return timed(layout(200, 200, labels), 0.5);
    };
    const SequenceMetrics m =
        sequence_metrics({frame(1.0, 0.5, true), frame(0.4, 0.5, false), frame(0.6, 1.0, false)});
    CHECK(m.label_frame_pairs == 4);
    CHECK(m.opaque_flips == 2);
    CHECK(m.show_hide_flips == 0);  // (all placed throughout)
    REQUIRE(m.opaque_flips_per_label_per_second);
    CHECK(*m.opaque_flips_per_label_per_second == doctest::Approx(1.0));
    CHECK(*m.seconds == doctest::Approx(1.0));
  }

  TEST_CASE("per_second_figures_are_null_when_a_frame_has_no_seconds") {
    const Layout a = layout(100, 100, {offset_label(1, {10, 10}, {20, 0})});
    const Layout b = layout(100, 100, {offset_label(1, {10, 10}, {30, 0})});
    // Frame 0's seconds are not used: the step from k to k + 1 is frame k + 1's.
    const SequenceMetrics first_only = sequence_metrics({timed(a, 0.1), b});
    CHECK_FALSE(first_only.seconds);
    CHECK_FALSE(first_only.motion_mean);
    CHECK_FALSE(first_only.opaque_flips_per_label_per_second);
    CHECK(first_only.opaque_jumps == 1);  // 10 px of 100: no time needed
    const nlohmann::ordered_json report = to_json(first_only);
    CHECK(report["sequence"]["motion_mean_of_width_per_second"].is_null());
    CHECK(report["sequence"]["opaque_flips_per_label_per_second"].is_null());
    const SequenceMetrics second_only = sequence_metrics({a, timed(b, 0.1)});
    REQUIRE(second_only.motion_mean);
    CHECK(*second_only.motion_mean == doctest::Approx(1.0));
    CHECK_FALSE(sequence_metrics({timed(a, 0.1)}).seconds);  // one frame: no duration
  }

  TEST_CASE("opaque_labels_compare_with_stills_of_the_same_views") {
    const auto frame = [](double opacity) {
      return layout(
          100, 100,
          {fading(internal_label(1, {0, 0}, {10, 10}), opacity),
           internal_label(2, {20, 0}, {10, 10}), internal_label(3, {40, 0}, {10, 10}, false)});
    };
    const Layout still =
        layout(100, 100,
               {internal_label(1, {0, 0}, {10, 10}), internal_label(2, {20, 0}, {10, 10}),
                internal_label(3, {40, 0}, {10, 10})});
    const SequenceMetrics m = sequence_metrics({frame(0.3), frame(1.0)}, {still, still});
    REQUIRE(m.stills.size() == 2);
    CHECK(m.stills_total.opaque == 6);
    const nlohmann::ordered_json report = to_json(m);
    CHECK(report["per_frame"][0]["still_opaque"] == 3);
    CHECK(report["per_frame"][0]["opaque_of_still"].get<double>() == doctest::Approx(1.0 / 3.0));
    CHECK(report["per_frame"][1]["opaque_of_still"].get<double>() == doctest::Approx(2.0 / 3.0));
    CHECK(report["total"]["opaque_of_still"].get<double>() == doctest::Approx(0.5));
    CHECK(report["total"]["still_leader_crossings"] == 0);
    // Without stills the keys are left out; the summary leaves out the frames.
    CHECK_FALSE(to_json(sequence_metrics({frame(1.0)}))["total"].contains("opaque_of_still"));
    CHECK_FALSE(to_json(m, false).contains("per_frame"));
    // A still of another size, or one still too few, is an error.
    CHECK(test::error_of([&] {
            sequence_metrics({frame(1.0)}, {layout(50, 100, {})});
          }).find("a still of 50x100 for a frame of 100x100") != std::string::npos);
    CHECK(test::error_of([&] {
            sequence_metrics({frame(1.0), frame(1.0)}, {still});
          }) == "stills: 1 layouts for 2 frames");
  }

  // Frames of labels 1, 2, ... given as one string each, a character per frame: 'R' readable,
  // 'f' shown but fading (opacity 0.3), '-' hidden with its anchor in the image, 'o' hidden with
  // its anchor outside it, ' ' not in the file. Every frame has the time step `step`.
  std::vector<Layout> labelled_frames(const std::vector<std::string>& labels,
                                      std::optional<double> step) {
    std::vector<Layout> frames(labels.front().size(), layout(100, 100, {}));
    for (size_t k = 0; k < frames.size(); ++k) {
      frames[k].seconds = step;
      for (size_t i = 0; i < labels.size(); ++i) {
        const char c = labels[i][k];
        if (c == ' ') continue;
        LayoutLabel l = label(int(i) + 1, {c == 'o' ? -10.0 : 50.0, 50}, {60, 40}, {20, 10},
                              c == 'R' || c == 'f');
        l.placed = l.shown;
        if (c == 'f') l = fading(l, 0.3);
        frames[k].labels.push_back(l);
      }
    }
    return frames;
  }

  TEST_CASE("a_label_hidden_or_faded_for_one_frame_mid_stretch_has_one_extra_range") {
    const ActiveRangeMetrics m = sequence_metrics(labelled_frames({"RRRR-RRRR"}, 0.5)).ranges;
    CHECK(m.visible_stretches == 1);
    CHECK(m.active_ranges == 2);
    CHECK(m.extra_ranges == 1);
    CHECK(m.readable_label_frames == 8);
    REQUIRE(m.readable_label_seconds);
    CHECK(*m.readable_label_seconds == doctest::Approx(3.5));  // frame 0 weighs nothing
    REQUIRE(m.extra_ranges_per_label_per_second);
    CHECK(*m.extra_ranges_per_label_per_second == doctest::Approx(1.0 / 4.0));  // 8 pairs of 0.5 s
    const ActiveRangeMetrics faded = sequence_metrics(labelled_frames({"RRfRR"}, 0.5)).ranges;
    CHECK(faded.active_ranges == 2);
    CHECK(faded.extra_ranges == 1);
    // A label always readable, beside it, adds a range and its label-seconds, no extra range.
    const ActiveRangeMetrics two =
        sequence_metrics(labelled_frames({"RRRR-RRRR", "RRRRRRRRR"}, 0.5)).ranges;
    CHECK(two.active_ranges == 3);
    CHECK(two.extra_ranges == 1);
    CHECK(*two.extra_ranges_per_label_per_second == doctest::Approx(1.0 / 8.0));
  }

  TEST_CASE("a_half_second_range_in_the_middle_is_short_and_at_the_ends_is_counted_apart") {
    // At 0.25 s a frame: label 1's ranges are frames 0-1 (0.25 s: frame 0 weighs nothing), 4-5
    // (0.5 s) and 8-9 (0.5 s): three short, one inside. Label 2's 1 s in the middle is not short.
    const ActiveRangeMetrics m =
        sequence_metrics(labelled_frames({"RR--RR--RR", "--RRRR----"}, 0.25)).ranges;
    CHECK(m.active_ranges == 4);
    CHECK(m.extra_ranges == 2);
    REQUIRE(m.short_ranges);
    CHECK(*m.short_ranges == 3);
    REQUIRE(m.short_ranges_inside);
    CHECK(*m.short_ranges_inside == 1);
    // Ten steps of 0.1 s sum to a hair under 1 s in doubles: still 1 s, not short.
    const ActiveRangeMetrics tenths =
        sequence_metrics(labelled_frames({"-RRRRRRRRRR-"}, 0.1)).ranges;
    CHECK(*tenths.short_ranges == 0);
  }

  TEST_CASE("a_label_leaving_the_image_or_the_file_and_returning_starts_a_new_stretch") {
    const ActiveRangeMetrics out = sequence_metrics(labelled_frames({"RRRoooRRR"}, 0.5)).ranges;
    CHECK(out.visible_stretches == 2);
    CHECK(out.active_ranges == 2);
    CHECK(out.extra_ranges == 0);
    const ActiveRangeMetrics gone = sequence_metrics(labelled_frames({"RRR   RRR"}, 0.5)).ranges;
    CHECK(gone.visible_stretches == 2);
    CHECK(gone.extra_ranges == 0);
    // Out of the image between two ranges, even when back in it for a frame: no extra range;
    // hidden in view: one stretch, one extra range.
    CHECK(sequence_metrics(labelled_frames({"RRo-oRR"}, 0.5)).ranges.extra_ranges == 0);
    CHECK(sequence_metrics(labelled_frames({"RR---RR"}, 0.5)).ranges.extra_ranges == 1);
  }

  TEST_CASE("range_counts_stay_and_per_second_figures_are_null_without_seconds") {
    const SequenceMetrics m = sequence_metrics(labelled_frames({"RR-RR", "-RRRR"}, std::nullopt));
    CHECK(m.ranges.active_ranges == 3);
    CHECK(m.ranges.extra_ranges == 1);
    CHECK(m.ranges.readable_label_frames == 8);
    CHECK_FALSE(m.ranges.readable_label_seconds);
    CHECK_FALSE(m.ranges.extra_ranges_per_label_per_second);
    CHECK_FALSE(m.ranges.short_ranges);
    CHECK_FALSE(m.ranges.short_ranges_inside);
    const nlohmann::ordered_json sequence = to_json(m)["sequence"];
    CHECK(sequence["extra_ranges"] == 1);
    CHECK(sequence["readable_label_seconds"].is_null());
    CHECK(sequence["short_ranges_inside"].is_null());
    CHECK_FALSE(sequence.contains("readable_of_stills"));
    // Frame 0's seconds are not needed; one frame has no duration.
    std::vector<Layout> frames = labelled_frames({"RRR"}, 0.5);
    frames[0].seconds.reset();
    CHECK(sequence_metrics(frames).ranges.readable_label_seconds);
    CHECK_FALSE(sequence_metrics(labelled_frames({"R"}, 0.5)).ranges.short_ranges);
  }

  TEST_CASE("readable_label_seconds_compare_with_the_stills_of_the_same_frames") {
    // Frames 1-3 weigh 0.5 s: the sequence reads 3 + 1 label-frames, the stills 3 + 3.
    const std::vector<Layout> stills = labelled_frames({"----", "----"}, std::nullopt);
    const std::vector<Layout> readable_stills = labelled_frames({"RRRR", "RRRR"}, std::nullopt);
    const SequenceMetrics m =
        sequence_metrics(labelled_frames({"RRRR", "R--R"}, 0.5), readable_stills);
    REQUIRE(m.ranges.still_readable_label_seconds);
    CHECK(*m.ranges.still_readable_label_seconds == doctest::Approx(3.0));
    CHECK(*m.ranges.readable_label_seconds == doctest::Approx(2.0));
    REQUIRE(m.ranges.readable_of_stills);
    CHECK(*m.ranges.readable_of_stills == doctest::Approx(2.0 / 3.0));
    const nlohmann::ordered_json sequence = to_json(m)["sequence"];
    CHECK(sequence["readable_of_stills"].get<double>() == doctest::Approx(2.0 / 3.0));
    // Stills that read nothing give no ratio.
    const SequenceMetrics none = sequence_metrics(labelled_frames({"RRRR", "R--R"}, 0.5), stills);
    CHECK(*none.ranges.still_readable_label_seconds == 0.0);
    CHECK_FALSE(none.ranges.readable_of_stills);
    CHECK(to_json(none)["sequence"]["readable_of_stills"].is_null());
  }

  TEST_CASE("the_bound_keeps_each_stretchs_longest_readable_still_run_of_a_second_or_at_an_end") {
    // 0.25 s a frame. Label 1: runs 0-1, 3-7 (1.25 s) and 9 in one stretch: 1.25 s. Label 2: one
    // run of 0.75 s inside: nothing. Label 3: out of view at 2 and 8, so three stretches, each
    // its run: 0.25 (at the start; frame 0 weighs nothing) + 1.25 + 0.25 (at the end).
    // (Stills have no seconds: they weigh as their frames.)
    const std::vector<Layout> stills =
        labelled_frames({"RR-RRRRR-R", "--RRR-----", "RRoRRRRRoR"}, std::nullopt);
    const std::vector<Layout> frames =
        labelled_frames({"RRRRRRRRRR", "----------", "----------"}, 0.25);
    const ActiveRangeMetrics m = sequence_metrics(frames, stills).ranges;
    REQUIRE(m.bound_label_seconds);
    CHECK(*m.bound_label_seconds == doctest::Approx(3.0));
    CHECK(best_consistent_seconds(stills, frame_weights(frames)) == doctest::Approx(3.0));
    REQUIRE(m.readable_of_bound);
    CHECK(*m.readable_of_bound == doctest::Approx(2.25 / 3.0));
    CHECK(to_json(sequence_metrics(
        labelled_frames({"R--", "---", "---"}, 0.25),
        labelled_frames({"---", "---", "---"}, std::nullopt)))["sequence"]["readable_of_bound"]
              .is_null());
  }

  TEST_CASE("a_first_plan_keeps_each_labels_longest_run_per_stretch_from_its_fade_to_the_end") {
    // 0.25 s a frame, a lead of 0.3 s (two frames). Label 1: runs 0-1 and 4-9 (1.5 s): from 2 to
    // the stretch's end. Label 2: runs 0-1 and 3, equally long: the first, from 0. Label 3 is
    // never drawn, label 4 only 0.5 s inside: neither has a range. Label 5: out of view at 5,
    // a range in each stretch.
    const ActiveRanges plan = first_plan(
        labelled_frames(
            {"RR--RRRRRR--", "RR-R--------", "------------", "----RR------", "RRRRRoRRRRRR"}, 0.25),
        0.3);
    CHECK(plan.size() == 3);
    CHECK(plan.at(1) == std::vector<FrameRange>{{2, 11}});
    CHECK(plan.at(2) == std::vector<FrameRange>{{0, 11}});
    CHECK(plan.at(5) == std::vector<FrameRange>{{0, 4}, {6, 11}});
  }

  TEST_CASE("drop_short_ranges_removes_the_ranges_a_rehearsal_drew_short_inside") {
    ActiveRanges plan{{1, {{2, 11}}}, {2, {{0, 11}}}, {3, {{0, 5}, {7, 11}}}};
    // Label 1 drawn 0.5 s inside its range: dropped. Label 2 drawn 0.25 s from frame 0: at the
    // start, kept. Label 3: 1.25 s in its first range, 0.5 s up to the last frame: both kept.
    const size_t dropped = drop_short_ranges(
        plan, labelled_frames({"----RR------", "RR----------", "RRRRRR-RRRRR"}, 0.25));
    CHECK(dropped == 1);
    CHECK_FALSE(plan.contains(1));
    CHECK(plan.at(2).size() == 1);
    CHECK(plan.at(3).size() == 2);
  }

  TEST_CASE("a_plan_follower_withholds_outside_ranges_and_after_a_range_ends_in_its_stretch") {
    // Label 1 (id 1) may show in frames 0-9; label 2 (id 7) has no range.
    PlanFollower follower({{1, {{0, 9}}}}, {1, 7});
    CHECK(follower.withheld(0) == std::vector<bool>{false, true});
    // Drawn, drawn, then not: withheld from then on while its anchor stays in view; out of view
    // ends the stretch, and in the next one it may show again.
    const std::vector<Layout> frames = labelled_frames({"RR-oRR-R--R"}, 0.25);
    const std::vector<bool> expected{false, false, true, false, false, false,
                                     true,  true,  true, true};  // (frame 10 is past the range)
    for (size_t k = 0; k + 1 < frames.size(); ++k) {
      CAPTURE(k);
      follower.saw(frames[k]);
      CHECK(follower.withheld(k + 1)[0] == expected[k]);
    }
  }

  TEST_CASE("read_layout_reads_opacity_target_and_seconds_and_defaults_them_for_older_files") {
    const auto folder = test::fresh_folder("cpu", "layout_metrics_read_motion");
    const auto path =
        test::write_file(folder / "layout.json",
                         R"({"width": 128, "height": 96, "seconds": 0.0625, "labels": [
          {"id": 1, "anchor": [10, 20], "box": [30, 40, 50, 12], "shown": true,
           "opacity": 0.25, "target": [35, 45, 50, 12]},
          {"id": 2, "anchor": [1, 2], "box": [1, 2, 4, 4], "shown": false, "target": null},
          {"id": 3, "anchor": [1, 2], "box": [1, 2, 4, 4], "shown": true},
          {"id": 4, "anchor": [1, 2], "box": [1, 2, 4, 4], "shown": false, "placed": true}]})");
    const Layout l = read_layout(path);
    REQUIRE(l.seconds);
    CHECK(*l.seconds == 0.0625);
    REQUIRE(l.labels.size() == 4);
    CHECK(l.labels[0].opacity == 0.25);
    REQUIRE(l.labels[0].target);
    CHECK(l.labels[0].target->min == glm::dvec2(35, 45));
    CHECK(l.labels[0].target->max == glm::dvec2(85, 57));
    CHECK_FALSE(l.labels[1].target);
    CHECK(l.labels[1].opacity == 0.0);
    // Older files: opacity 1 when drawn (placed), else 0; the target is the box.
    CHECK(l.labels[2].opacity == 1.0);
    REQUIRE(l.labels[2].target);
    CHECK(l.labels[2].target->min == glm::dvec2(1, 2));
    CHECK(l.labels[2].target->max == glm::dvec2(5, 6));
    CHECK(l.labels[3].opacity == 1.0);
    const auto still = test::write_file(
        folder / "still.json", R"({"width": 8, "height": 8, "seconds": null, "labels": []})");
    CHECK_FALSE(read_layout(still).seconds);
  }

  TEST_CASE("read_layout_reads_what_render_writes") {
    const auto folder = test::fresh_folder("cpu", "layout_metrics_read");
    const auto path = test::write_file(folder / "layout.json",
                                       R"({"width": 128, "height": 96, "labels": [
          {"id": 3, "text": "Caudate", "layer": 1, "anchor": [10.5, 20], "box": [30, 40, 50, 12],
           "shown": true, "cost": 0.25},
          {"id": 4, "anchor": [1, 2], "box": [1, 2, 0, 0], "shown": false, "cost": null,
           "from_a_later_version": 1}]})");
    const Layout l = read_layout(path);
    CHECK(l.width == 128);
    CHECK(l.height == 96);
    REQUIRE(l.labels.size() == 2);
    CHECK(l.labels[0].id == 3);
    CHECK(l.labels[0].text == "Caudate");
    CHECK(l.labels[0].layer == 1);
    CHECK(l.labels[0].anchor == glm::dvec2(10.5, 20));
    CHECK(l.labels[0].box_origin == glm::dvec2(30, 40));
    CHECK(l.labels[0].box_size == glm::dvec2(50, 12));
    CHECK(l.labels[0].shown);
    CHECK(l.labels[0].cost == 0.25);
    CHECK_FALSE(l.labels[1].shown);
    CHECK(std::isnan(l.labels[1].cost));
  }

  TEST_CASE("read_layout_errors_name_the_file_and_field") {
    const std::string head = R"({"width": 64, "height": 64, "labels": [)";
    const std::string good = R"({"id": 1, "anchor": [1, 2], "box": [0, 0, 4, 4], "shown": true})";
    const auto error = [&](const std::string& name, const std::string& labels) {
      return layout_error(name, head + labels + "]}");
    };
    CHECK(error("box", good + R"(, {"id": 2, "anchor": [1, 2], "box": [0, 0, 4], "shown": true})")
              .ends_with("layout.json: labels[1].box: expected 4 numbers"));
    CHECK(error("size", R"({"id": 2, "anchor": [1, 2], "box": [0, 0, -4, 4], "shown": true})")
              .ends_with("labels[0].box: width and height must be >= 0"));
    CHECK(error("anchor", R"({"id": 2, "anchor": [1, "2"], "box": [0, 0, 4, 4], "shown": 1})")
              .ends_with("labels[0].anchor: expected 2 numbers"));
    CHECK(error("shown", R"({"id": 2, "anchor": [1, 2], "box": [0, 0, 4, 4]})")
              .ends_with("labels[0]: missing key 'shown'"));
    CHECK(error("layer", R"({"id": 2, "anchor": [1, 2], "box": [0, 0, 4, 4], "shown": true,
                             "layer": -1})")
              .ends_with("labels[0].layer: expected an integer >= 0"));
    CHECK(error("duplicate", good + ", " + good)
              .ends_with("labels[1].id: duplicate id 1 (also labels[0])"));
    CHECK(layout_error("width", R"({"width": 0, "height": 64, "labels": []})")
              .ends_with("layout.json: width: expected a positive integer"));
    CHECK(error("opacity", R"({"id": 2, "anchor": [1, 2], "box": [0, 0, 4, 4], "shown": true,
                               "opacity": 1.5})")
              .ends_with("labels[0].opacity: expected a number from 0 to 1"));
    CHECK(error("target", R"({"id": 2, "anchor": [1, 2], "box": [0, 0, 4, 4], "shown": true,
                              "target": [0, 0, 4]})")
              .ends_with("labels[0].target: expected 4 numbers"));
    CHECK(layout_error("seconds", R"({"width": 8, "height": 8, "seconds": 0, "labels": []})")
              .ends_with("layout.json: seconds: expected a number > 0 or null"));
    CHECK(layout_error("labels", R"({"width": 8, "height": 64})")
              .ends_with("layout.json: missing key 'labels'"));
    CHECK(layout_error("syntax", R"({"width": 8,)").find("layout.json: parse error") !=
          std::string::npos);
    CHECK(test::error_of([] { read_layout("/nonexistent/layout.json"); }) ==
          "/nonexistent/layout.json: no such file");
  }
}

}  // namespace strata
