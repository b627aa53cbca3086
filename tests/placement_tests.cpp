// Label placement on lavapipe against its CPU reference (passes/placement_reference.h), stage
// by stage, on small hand-made inputs: a final image, layer images and labels.
//
// Tolerances: saliency and integral costs 1e-3 (pow and division differ in the last bits between
// CPU and GPU), tables 1e-5 of the larger value, constraint images exactly, positions within one
// pixel. Cost ties are broken by the lowest pixel index (row-major), on both sides.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>

#include <glm/gtc/packing.hpp>

#include "engine/core/error.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "frame/labelled_render.h"
#include "gpu_fixture.h"
#include "labeling/layout_metrics.h"
#include "passes/label_drawing.h"
#include "passes/label_forces.h"
#include "passes/placement.h"
#include "passes/placement_reference.h"
#include "test_scenes.h"

namespace strata {
namespace {

constexpr double kFrameSeconds = 1.0 / 30.0;           // a frame of a 30 fps animation
constexpr LabelUnits kUnits{1024.0f, 14.0f, 1024.0f};  // the forces' image and text size

struct Inputs {
  graph::Extent size{96, 72};
  uint32_t layer_count = 2;
  std::vector<uint8_t> final_rgba8;
  std::vector<glm::vec4> layers;
  std::vector<gpu::LabelGpu> labels;
  std::vector<uint32_t> order;
  std::vector<uint32_t> group_first;  // per order position (empty: one priority)
};

gpu::LabelGpu label(glm::vec2 anchor, glm::vec2 size, uint32_t layer) {
  return test::label_at(anchor, size, layer);
}

// A bright disc (the "object") on a dark background, half of it in the front layer, half in the
// back layer, with anchors on it; `scale` times the size of the default (96 x 72).
Inputs disc_scene(uint32_t label_count, float scale = 1.0f) {
  Inputs in;
  in.size = {uint32_t(96.0f * scale), uint32_t(72.0f * scale)};
  const size_t pixels = size_t{in.size.width} * in.size.height;
  in.final_rgba8.resize(pixels * 4);
  in.layers.assign(pixels * in.layer_count, glm::vec4(0.0f));
  const glm::vec2 centre = glm::vec2(48.0f, 36.0f) * scale;
  for (uint32_t y = 0; y < in.size.height; ++y) {
    for (uint32_t x = 0; x < in.size.width; ++x) {
      const size_t p = size_t{y} * in.size.width + x;
      const float r = glm::length(glm::vec2(x, y) + 0.5f - centre);
      const float a = glm::clamp((22.0f * scale - r) / 3.0f, 0.0f, 1.0f);
      const glm::vec3 c = glm::mix(
          glm::vec3(0.05f), glm::vec3(0.9f, 0.7f, 0.5f + 0.3f * std::sin(float(x) * 0.4f)), a);
      for (int ch = 0; ch < 3; ++ch)
        in.final_rgba8[4 * p + ch] = uint8_t(std::lround(c[ch] * 255.0f));
      in.final_rgba8[4 * p + 3] = 255;
      // Values as the rgba16f layer images hold them, so the reference sees the same inputs.
      glm::vec4 v(c * a * 0.8f, a * 0.8f);
      for (int ch = 0; ch < 4; ++ch) v[ch] = glm::unpackHalf1x16(glm::packHalf1x16(v[ch]));
      in.layers[(float(x) < centre.x ? 0 : 1) * pixels + p] = v;
    }
  }
  const glm::vec2 anchors[] = {{44, 30}, {55, 40}, {40, 44}, {52, 28}, {48, 36}, {60, 33}};
  for (uint32_t i = 0; i < label_count; ++i) {
    // (further round the disc for the labels past the first six)
    const glm::vec2 offset = float(i / 6) * glm::vec2(7.0f, -5.0f);
    in.labels.push_back(label(glm::floor((anchors[i % 6] + offset) * scale),
                              glm::floor(glm::vec2(20.0f + 2.0f * float(i), 8.0f) * scale), i % 2));
    in.order.push_back(i);
  }
  return in;
}

struct GpuPlacement {
  std::vector<float> saliency, costs, tables;
  std::vector<uint32_t> constraints;
  std::vector<gpu::PlacementGpu> placements;
  std::vector<gpu::PlacementBucketsGpu> buckets;  // per order position (and one more)
  std::vector<uint32_t> tidy_rounds;  // per tidy-up round: changes the round before applied
  std::vector<uint64_t> results;      // per label: the greedy placement's (cost, pixel)
  std::vector<uint32_t> round_of;     // per label: the round that decided it
  std::vector<uint32_t> round_counts;  // per round: labels undecided before it
};

template <typename T>
std::vector<T> as(const std::vector<std::byte>& bytes) {
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

// A frame of 1/30 s after one that left `previous`: the forces' state that the labels take their
// previous and held positions and their padding from (LabelForces::add_previous, with `forces`).
GpuPlacement place_on_gpu(Context& ctx, const Inputs& in, const PlacementSettings& settings,
                          const PlacementLayout& layout = {},
                          const std::vector<gpu::LabelStateGpu>& previous = {},
                          const ForceSettings& forces = {}) {
  Image final_image(ctx, {VK_FORMAT_R8G8B8A8_UNORM,
                          {in.size.width, in.size.height, 1},
                          VK_IMAGE_TYPE_2D,
                          VK_IMAGE_USAGE_STORAGE_BIT});
  upload(ctx, final_image, as_bytes(in.final_rgba8), VK_IMAGE_LAYOUT_GENERAL);
  const Image layers = test::layer_image(ctx, in.size, in.layer_count, in.layers);

  Placement placement(ctx, uint32_t(in.labels.size()), layout);
  graph::Graph g;
  const auto general = [&g](const char* name, const Image& image) {
    return g.import_image(name, {.image = image.handle(),
                                 .view = image.view(),
                                 .format = image.desc().format,
                                 .has_content = true,
                                 .initial_layout = VK_IMAGE_LAYOUT_GENERAL});
  };
  Buffer state(ctx, std::max<size_t>(1, previous.size()) * sizeof(gpu::LabelStateGpu),
               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::device_local);
  if (!previous.empty()) upload(ctx, state, as_bytes(previous));
  LabelForces last_frame(ctx, uint32_t(in.labels.size()));
  last_frame.set_frame(forces, kUnits, kFrameSeconds, settings.hard);
  Placement::AdjustLabels adjust;
  if (!previous.empty()) {
    const graph::ResourceId state_id =
        g.import_buffer("state", {.buffer = state.handle(), .has_content = true});
    adjust = [&last_frame, state_id](graph::Graph& graph, graph::ResourceId labels) {
      last_frame.add_previous(graph, labels, state_id);
    };
  }
  const Placement::Outputs r = placement.add_to(g, {.final_image = general("final", final_image),
                                                    .layers = general("layers", layers),
                                                    .layer_count = in.layer_count,
                                                    .adjust_labels = adjust});
  graph::GraphRunner runner(ctx, std::move(g));
  runner.set_viewport(in.size);
  placement.set_frame(in.labels, in.order, settings, {}, in.group_first);
  runner.run_now();
  GpuPlacement out;
  out.saliency = as<float>(runner.download_buffer(r.saliency));
  out.costs = as<float>(runner.download_buffer(r.costs));
  out.tables = as<float>(runner.download_buffer(r.tables));
  out.constraints = as<uint32_t>(runner.download_buffer(r.constraints));
  out.buckets = as<gpu::PlacementBucketsGpu>(runner.download_buffer(r.buckets));
  out.tidy_rounds = as<uint32_t>(runner.download_buffer(r.tidy_rounds));
  out.results = as<uint64_t>(runner.download_buffer(r.results));
  out.round_of = as<uint32_t>(runner.download_buffer(r.round_of));
  out.round_counts = as<uint32_t>(runner.download_buffer(r.round_counts));
  const auto results = placement.results();
  out.placements.assign(results.begin(), results.end());
  return out;
}

void check_values(const std::vector<float>& gpu, const std::vector<float>& cpu, float tolerance,
                  bool relative, const std::string& what) {
  REQUIRE(gpu.size() >= cpu.size());
  size_t bad = 0;
  for (size_t i = 0; i < cpu.size(); ++i) {
    const float scale = relative ? std::max(1.0f, std::abs(cpu[i])) : 1.0f;
    if (std::abs(gpu[i] - cpu[i]) > tolerance * scale && bad++ < 3) {
      MESSAGE(what << "[" << i << "]: gpu " << gpu[i] << " cpu " << cpu[i]);
    }
  }
  CHECK_MESSAGE(bad == 0, what << ": " << bad << " values differ");
}

void check_placements(const GpuPlacement& gpu, const ReferencePlacement& cpu) {
  REQUIRE(gpu.placements.size() == cpu.placements.size());
  for (size_t i = 0; i < cpu.placements.size(); ++i) {
    CAPTURE(i);
    CHECK(gpu.placements[i].shown == cpu.placements[i].shown);
    CHECK(std::abs(gpu.placements[i].position.x - cpu.placements[i].position.x) <= 1.0f);
    CHECK(std::abs(gpu.placements[i].position.y - cpu.placements[i].position.y) <= 1.0f);
  }
}

// The GPU's positions match the reference's with each bucket width, dispatched directly and
// indirectly.
void check_placements_across(Context& ctx, const Inputs& in, const ReferencePlacement& cpu,
                             std::initializer_list<float> bucket_widths) {
  for (const float width : bucket_widths) {
    for (const LabelDispatch dispatch : {LabelDispatch::direct, LabelDispatch::indirect}) {
      CAPTURE(width);
      CAPTURE(int(dispatch));
      PlacementSettings settings;
      settings.bucket_width = width;
      check_placements(place_on_gpu(ctx, in, settings, {.dispatch = dispatch}), cpu);
    }
  }
}

// The GPU's placement with `settings`, checked against the reference's: integral costs and hidden
// pixels, their tables, the positions.
std::vector<gpu::PlacementGpu> place_checked(Context& ctx, const Inputs& in,
                                             const PlacementSettings& settings) {
  const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
  const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                 in.labels, in.order, settings, in.size);
  check_values(gpu.costs, cpu.costs, 1e-3f, false, "integral costs and hidden pixels");
  check_values(gpu.tables, cpu.tables, 1e-5f, true, "tables");
  check_placements(gpu, cpu);
  return gpu.placements;
}

// The placements as a layout, for strata eval's counts.
FrameMetrics metrics_of(const Inputs& in, const std::vector<gpu::PlacementGpu>& placements) {
  Layout layout{.source = "placement", .width = in.size.width, .height = in.size.height};
  for (size_t i = 0; i < placements.size(); ++i) {
    const gpu::PlacementGpu& p = placements[i];
    LayoutLabel l;
    l.id = int(i);
    l.anchor = in.labels[i].anchor;
    l.box_size = in.labels[i].size;
    l.box_origin = glm::dvec2(p.position) - l.box_size * 0.5;
    l.shown = l.placed = p.shown == PLACEMENT_SHOWN;
    layout.labels.push_back(l);
  }
  return frame_metrics(layout);
}

// `count` labels of size `box` on a grey picture with empty layers, their anchors spread over
// it `margin` pixels from its edges, two layers alternating, in label order.
Inputs crowded_scene(graph::Extent size, float margin, uint32_t count, glm::vec2 box) {
  Inputs in = disc_scene(0);
  in.size = size;
  const size_t pixels = size_t{size.width} * size.height;
  in.final_rgba8.assign(pixels * 4, 40);
  in.layers.assign(pixels * in.layer_count, glm::vec4(0.0f));
  const uint32_t w = uint32_t(float(size.width) - 2.0f * margin);
  const uint32_t h = uint32_t(float(size.height) - 2.0f * margin);
  for (uint32_t i = 0; i < count; ++i) {
    const glm::vec2 anchor(margin + float(i * 7 % w), margin + float(i * 5 % h));
    in.labels.push_back(label(anchor, box, i % 2));
    in.order.push_back(i);
  }
  return in;
}

// Whether a box (centre, size) touches the rectangle k ([lo, hi) pixels).
bool touches(glm::vec2 centre, glm::vec2 size, glm::uvec4 k) {
  const glm::vec2 lo = centre - 0.5f * size, hi = centre + 0.5f * size;
  return lo.x < float(k.z) && lo.y < float(k.w) && float(k.x) < hi.x && float(k.y) < hi.y;
}

}  // namespace

TEST_SUITE("cpu") {
  // The conflict test itself: two labels whose boxes overlap conflict, one far away does not.
  TEST_CASE("labels_whose_boxes_or_leaders_touch_conflict_in_a_round") {
    const graph::Extent size{64, 64};
    const PlacementSettings settings;
    const auto key = [&](glm::uvec2 p) { return uint64_t(p.y * size.width + p.x); };
    const gpu::LabelGpu a = label({10, 10}, {12, 6}, 0), b = label({30, 10}, {12, 6}, 0);
    CHECK(rounds_conflict_reference(a, key({20, 20}), b, key({22, 22}), settings, size));
    CHECK_FALSE(rounds_conflict_reference(a, key({8, 30}), b, key({40, 30}), settings, size));
    // b's leader from (30, 10) down to (8, 40) passes a's box at (14, 30)
    CHECK(rounds_conflict_reference(a, key({16, 30}), b, key({8, 45}), settings, size));
    CHECK_FALSE(rounds_conflict_reference(a, PLACEMENT_NONE, b, key({22, 22}), settings, size));
  }

  // Past 256 labels a round of the tidy-up weighs every conflicted label's moves and every
  // crossing pair against all labels: the rounds asked for are capped, 64 (256 / n)^2 at most
  // and at least one, so a frame of 4096 labels ends; up to 256 labels, as asked.
  TEST_CASE("tidy_up_rounds_are_capped_past_256_labels") {
    PlacementSettings settings;  // 64 rounds
    const auto rounds = [&](uint32_t labels) {
      return placement_params(settings, {1024, 1024}, 4, labels, 0).tidy_rounds;
    };
    CHECK(rounds(100) == 64);
    CHECK(rounds(256) == 64);
    CHECK(rounds(500) == 16);
    CHECK(rounds(1000) == 4);
    CHECK(rounds(4096) == 1);
    settings.tidy_rounds = 2;
    CHECK(rounds(500) == 2);
    settings.tidy_rounds = 300;
    CHECK(rounds(100) == TIDY_ROUNDS_MAX);
    settings.hard = true;
    CHECK(rounds(100) == 0);
  }
}

TEST_SUITE("gpu") {
  // Labels pulled by eq. 3.1's eta term to previous positions on the far side of each other's
  // anchors, with no cost for crossing an earlier leader: the greedy placement leaves two pairs of
  // crossing leaders; the tidy-up swaps them (on the GPU as in the reference), with no overlap,
  // and without hiding a label.
  // Past TIDY_SHARED_MAX labels the tidy-up's shaders read the labels' states from the buffer
  // (placement_tidy_large.comp, placement_tidy_search_large.comp): the same layout as the
  // reference, with rounds that change it.
  TEST_CASE_FIXTURE(test::GpuTest, "past_256_labels_the_tidy_up_reads_the_states_from_the_buffer") {
    const Inputs in = crowded_scene({64, 48}, 4.0f, TIDY_SHARED_MAX + 4, {6.0f, 4.0f});
    PlacementSettings settings;
    settings.tidy_rounds = 2;
    const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, settings, in.size);
    check_placements(gpu, cpu);
    REQUIRE(gpu.tidy_rounds.size() > 1);
    CHECK(gpu.tidy_rounds[1] > 0);  // (round 0 applied changes)
  }

  TEST_CASE_FIXTURE(test::GpuTest, "past_1024_labels_the_upload_holds_every_label") {
    // 1030 labels are 65920 bytes: more than one vkCmdUpdateBuffer may take (65536).
    Inputs in = crowded_scene({16, 12}, 2.0f, 1030, {2.0f, 2.0f});
    std::reverse(in.order.begin(), in.order.end());  // (the labels past the first 1024 go first)
    PlacementSettings settings;
    settings.tidy_rounds = 0;
    const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, settings, in.size);
    check_placements(gpu, cpu);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "the_layout_tidy_up_removes_leader_crossings") {
    Inputs in;
    in.size = {160, 120};
    in.layer_count = 1;
    in.final_rgba8.assign(size_t(160) * 120 * 4, 20);
    in.layers.assign(size_t(160) * 120, glm::vec4(0.0f));
    const glm::vec2 anchors[] = {{60, 50}, {100, 50}, {60, 80}, {100, 80}};
    const glm::vec2 previous[] = {{130, 20}, {30, 20}, {130, 104}, {30, 104}};
    for (uint32_t i = 0; i < 4; ++i) {
      in.labels.push_back(label(anchors[i], {30.0f, 10.0f}, 0));
      in.labels.back().previous = previous[i];
      in.order.push_back(i);
    }
    PlacementSettings settings;
    settings.weights.connector_shadow = 0.0f;
    settings.weights.previous_position = 1.0f;
    settings.tidy_rounds = 0;
    const GpuPlacement greedy = place_on_gpu(ctx, in, settings);
    const FrameMetrics before = metrics_of(in, greedy.placements);
    MESSAGE("greedy: " << before.leader_crossings << " crossings, " << before.leaders_through_boxes
                       << " leaders through boxes");
    REQUIRE(before.leader_crossings == 2);
    settings.tidy_rounds = 64;
    const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, settings, in.size);
    check_placements(gpu, cpu);
    const FrameMetrics after = metrics_of(in, gpu.placements);
    CHECK(after.leader_crossings == 0);
    CHECK(after.overlaps == 0);
    CHECK(after.anchors_covered == 0);
    CHECK(after.shown == in.labels.size());
    CHECK(after.leaders_through_boxes <= before.leaders_through_boxes);
  }

  // A near-opaque slab on the front layer over the left two thirds of the image (or all of it),
  // nothing else, no integral costs: a rear label anchored under the slab would sit on it,
  // unreadable. The illegible weight moves it off the slab (soft mode); hard mode forbids the
  // slab (and hides the label when the slab covers everything); a front-layer label is not
  // concerned. GPU == reference throughout; the visibility strata reports agrees.
  TEST_CASE_FIXTURE(test::GpuTest, "placement_avoids_boxes_the_front_layers_hide") {
    const auto slab_scene = [](float slab_end) {
      Inputs in;
      in.size = {96, 72};
      const size_t pixels = size_t{in.size.width} * in.size.height;
      in.final_rgba8.assign(pixels * 4, 90);
      in.layers.assign(pixels * 2, glm::vec4(0.0f));
      for (uint32_t y = 0; y < in.size.height; ++y) {
        for (uint32_t x = 0; x < in.size.width; ++x) {
          const float a = glm::unpackHalf1x16(glm::packHalf1x16(0.875f));
          if (float(x) < slab_end)
            in.layers[size_t{y} * in.size.width + x] = glm::vec4(0.3f * a, 0.3f * a, 0.3f * a, a);
        }
      }
      in.labels = {label({30.0f, 36.0f}, {20.0f, 8.0f}, 1),
                   label({20.0f, 20.0f}, {16.0f, 8.0f}, 0)};
      in.order = {0, 1};
      return in;
    };
    const auto visible = [](const Inputs& in, const std::vector<gpu::PlacementGpu>& placements) {
      std::vector<LabelLayout> layout;
      for (size_t i = 0; i < placements.size(); ++i) {
        LabelLayout l;
        l.layer = in.labels[i].layer;
        l.box_size = in.labels[i].size;
        l.box_origin = placements[i].position - l.box_size * 0.5f;
        l.placed = placements[i].shown == PLACEMENT_SHOWN;
        layout.push_back(l);
      }
      return label_visibility(in.layers, in.size, in.layer_count, layout);
    };
    const auto place = [&](const Inputs& in, float illegible, bool hard) {
      PlacementSettings settings;
      settings.weights.integral_costs = 0.0f;
      settings.weights.illegible = illegible;
      settings.hard = hard;
      settings.write_constraints = true;
      return place_checked(ctx, in, settings);
    };
    const Inputs in = slab_scene(64.0f);
    // (unaware: the rear label on the slab, next to its anchor)
    const std::vector<gpu::PlacementGpu> unaware = place(in, 0.0f, false);
    REQUIRE(unaware[0].shown == PLACEMENT_SHOWN);
    CHECK(visible(in, unaware)[0] < kLegibleShare);
    for (const bool hard : {false, true}) {
      CAPTURE(hard);
      const std::vector<gpu::PlacementGpu> aware = place(in, hard ? 0.0f : 1000.0f, hard);
      const std::vector<float> seen = visible(in, aware);
      REQUIRE(aware[0].shown == PLACEMENT_SHOWN);
      CHECK(seen[0] >= kLegibleShare);
      CHECK(aware[0].position.x - 10.0f >= 64.0f - 0.25f * 20.0f);  // at most a quarter on the slab
      // The front-layer label stays by its anchor, on the slab.
      CHECK(aware[1].shown == PLACEMENT_SHOWN);
      CHECK(glm::distance(aware[1].position, unaware[1].position) <= 1.0f);
      CHECK(seen[1] == 1.0f);
    }
    // Nowhere legible: hard mode hides the rear label, soft mode shows it (and says it costs).
    const Inputs covered = slab_scene(96.0f);
    CHECK(place(covered, 0.0f, true)[0].shown == PLACEMENT_HIDDEN);
    const std::vector<gpu::PlacementGpu> soft = place(covered, 1000.0f, false);
    CHECK(soft[0].shown == PLACEMENT_SHOWN);
    CHECK(soft[0].cost >= 1000.0f);
    CHECK(place(covered, 0.0f, true)[1].shown == PLACEMENT_SHOWN);
  }

  // A near-opaque slab over the whole front layer, something to see on the rear layer: hard mode
  // finds no legible box for the rear label and hides it. With ghosting its lens will open the
  // slab around its anchor, and the placement counts that: the label is placed in its lens
  // (GPU == reference, the hidden pixels too), and the layers as the ghosting pass leaves them
  // show its box. A weak lens (strength 0.3) leaves the slab hiding it.
  TEST_CASE_FIXTURE(test::GpuTest, "boxes_a_ghosting_lens_opens_count_as_legible") {
    Inputs in;
    in.size = {96, 72};
    const size_t pixels = size_t{in.size.width} * in.size.height;
    in.final_rgba8.assign(pixels * 4, 90);
    const float front = glm::unpackHalf1x16(glm::packHalf1x16(0.875f));
    const float rear = glm::unpackHalf1x16(glm::packHalf1x16(0.625f));
    in.layers.assign(pixels, glm::vec4(0.3f * front, 0.3f * front, 0.3f * front, front));
    in.layers.resize(2 * pixels, glm::vec4(0.5f * rear, 0.2f * rear, 0.2f * rear, rear));
    in.labels = {label({48.0f, 36.0f}, {20.0f, 8.0f}, 1)};
    in.order = {0};
    const auto place = [&](float strength) {
      PlacementSettings settings;
      settings.weights.integral_costs = 0.0f;
      settings.hard = true;
      settings.ghost_strength = strength;
      settings.ghost_radius = 30.0f;
      return place_checked(ctx, in, settings);
    };
    CHECK(place(0.0f)[0].shown == PLACEMENT_HIDDEN);
    CHECK(place(0.3f)[0].shown == PLACEMENT_HIDDEN);
    std::vector<gpu::PlacementGpu> ghosted = place(1.0f);
    REQUIRE(ghosted[0].shown == PLACEMENT_SHOWN);
    CHECK(glm::distance(ghosted[0].position, in.labels[0].anchor) < 30.0f);
    ghosted[0].opacity = 1.0f;  // (as the forces draw a shown label)
    const std::vector<glm::vec4> opened = ghost_reference(
        in.layers, in.size, in.layer_count, {.labels = in.labels, .placements = ghosted},
        {.strength = 1.0f, .radius = 30.0f});
    LabelLayout l;
    l.layer = 1;
    l.box_size = in.labels[0].size;
    l.box_origin = ghosted[0].position - l.box_size * 0.5f;
    l.placed = true;
    CHECK(label_visibility(opened, in.size, in.layer_count, std::vector{l})[0] >= kLegibleShare);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "placement_stages_and_positions_match_the_cpu_reference") {
    for (uint32_t count : {3u, 6u}) {
      CAPTURE(count);
      const Inputs in = disc_scene(count);
      // (the constraint image is the sequential loop's: the last label's constraints)
      PlacementSettings settings;
      settings.method = PlacementMethod::sequential;
      settings.write_constraints = true;
      const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
      const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                     in.labels, in.order, settings, in.size);
      check_values(gpu.saliency, cpu.saliency, 1e-3f, false, "saliency");
      check_values(gpu.costs, cpu.costs, 1e-3f, false, "integral costs");
      check_values(gpu.tables, cpu.tables, 1e-5f, true, "tables");
      CHECK(gpu.constraints == cpu.constraints);
      check_placements(gpu, cpu);
      // Without the constraint image, tiles that cannot beat the best cost so far are skipped:
      // the positions must not change.
      settings.write_constraints = false;
      check_placements(place_on_gpu(ctx, in, settings), cpu);
      size_t shown = 0;
      for (const auto& p : gpu.placements) shown += p.shown == PLACEMENT_SHOWN;
      CHECK(shown == count);
    }
  }

  // Keep-out rectangles (the viewer's panel, a title, a legend; an empty one counts for nothing):
  // no box touches any, in the sequential loop with its tidy-up and in the rounds, and the GPU
  // equals the reference, which places labels elsewhere than without them.
  TEST_CASE_FIXTURE(test::GpuTest, "no_box_is_placed_on_any_keep_out_rectangle") {
    const Inputs in = disc_scene(6);
    const ReferencePlacement free = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                    in.labels, in.order, {}, in.size);
    PlacementSettings settings;
    settings.keep_out = {{0u, 0u, 30u, in.size.height},               // a panel on the left
                         {30u, 0u, in.size.width, 16u},               // a title along the top
                         {5u, 5u, 5u, 9u},                            // empty
                         {70u, 50u, in.size.width, in.size.height}};  // a legend
    const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, settings, in.size);
    check_placements(gpu, cpu);
    size_t moved = 0, shown = 0;
    for (size_t i = 0; i < gpu.placements.size(); ++i) {
      const gpu::PlacementGpu& p = gpu.placements[i];
      moved += glm::length(p.position - free.placements[i].position) > 0.5f;
      if (p.shown != PLACEMENT_SHOWN) continue;
      ++shown;
      for (const glm::uvec4& k : settings.keep_out)
        CHECK_FALSE(touches(p.position, in.labels[i].size, k));
    }
    CHECK(shown >= 3);
    CHECK(moved >= 2);

    settings.method = PlacementMethod::rounds;
    settings.tidy_rounds = 0;
    const GpuPlacement rounds = place_on_gpu(ctx, in, settings);
    const ReferenceRounds reference =
        rounds_reference(in.labels, in.order, rounds.tables, settings, in.size, in.layer_count, {});
    for (size_t i = 0; i < in.labels.size(); ++i) {
      CHECK(uint32_t(rounds.results[i]) == uint32_t(reference.results[i]));
      if (rounds.placements[i].shown != PLACEMENT_SHOWN) continue;
      for (const glm::uvec4& k : settings.keep_out) {
        CHECK_FALSE(touches(rounds.placements[i].position, in.labels[i].size, k));
      }
    }

    settings.keep_out.assign(PLACEMENT_KEEP_OUT_MAX + 1, glm::uvec4(0u, 0u, 1u, 1u));
    CHECK_THROWS_AS(keep_out_rectangles(settings), Error);
  }

  // Eq. 3.1's eta with last frame's drawn positions (from the forces' state, on the GPU) gives
  // the reference's positions for those previous positions.
  TEST_CASE_FIXTURE(test::GpuTest, "previous_positions_come_from_the_forces_state") {
    Inputs in = disc_scene(4);
    std::vector<gpu::LabelStateGpu> state(in.labels.size());
    for (size_t i = 0; i < state.size(); ++i) {
      if (i == 3) continue;  // never drawn: its previous position stays the anchor
      state[i].position = glm::vec2(-16.0f + 8.0f * float(i), -9.0f);  // offset from the anchor
      state[i].drawn = in.labels[i].anchor + glm::vec2(-14.0f + 9.0f * float(i), 11.0f);
      state[i].flags = LABEL_STATE_PLACED | LABEL_STATE_SEEN;  // (not shown: nothing held)
    }
    for (const bool relative : {false, true}) {
      CAPTURE(relative);
      PlacementSettings settings;
      settings.weights.previous_position = 0.2f;
      const ForceSettings forces{.anchor_relative = relative};
      const gpu::ForcesParams params =
          forces_params(forces, kUnits, uint32_t(in.labels.size()), kFrameSeconds);
      const GpuPlacement gpu = place_on_gpu(ctx, in, settings, {}, state, forces);
      const std::vector<gpu::LabelGpu> expected = previous_reference(in.labels, state, params);
      for (size_t i = 0; i < 3; ++i) {
        CHECK(expected[i].previous ==
              (relative ? in.labels[i].anchor + state[i].position : state[i].drawn));
        CHECK(expected[i].hold == 0.0f);
      }
      CHECK(expected[3].previous == in.labels[3].anchor);
      const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                     expected, in.order, settings, in.size);
      check_placements(gpu, cpu);
      // The term matters here: with the anchors as previous positions the result differs.
      const ReferencePlacement anchored = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                          in.labels, in.order, settings, in.size);
      bool differs = false;
      for (size_t i = 0; i < cpu.placements.size(); ++i) {
        differs |= cpu.placements[i].position != anchored.placements[i].position;
      }
      CHECK(differs);
    }
  }

  // The hold: a label shown last frame keeps its target unless a position beats it by the hold.
  // With a large hold every held label stays (the held positions are free); with none they go
  // back to the fresh placement; GPU and reference agree either way.
  TEST_CASE_FIXTURE(test::GpuTest, "a_held_label_keeps_its_target_unless_a_move_wins_the_hold") {
    const Inputs in = disc_scene(4);
    const ReferencePlacement fresh = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                     in.labels, in.order, {}, in.size);
    // Last frame's targets: the fresh ones moved by a few pixels, each its own way.
    std::vector<gpu::LabelStateGpu> state(in.labels.size());
    for (size_t i = 0; i < state.size(); ++i) {
      const glm::vec2 moved =
          fresh.placements[i].position + glm::vec2(i % 2 == 0 ? 3.0f : -3.0f, i < 2 ? 2.0f : -2.0f);
      state[i].position = state[i].target = moved - in.labels[i].anchor;
      state[i].drawn = moved;
      state[i].cost = fresh.placements[i].cost;
      state[i].flags = LABEL_STATE_PLACED | LABEL_STATE_SHOWN | LABEL_STATE_SEEN;
    }
    for (const float hold : {0.0f, 1e3f}) {
      CAPTURE(hold);
      const ForceSettings forces{.hold_share = 0.0f, .hold_cost = hold};
      const gpu::ForcesParams params =
          forces_params(forces, kUnits, uint32_t(in.labels.size()), kFrameSeconds);
      const std::vector<gpu::LabelGpu> labels = previous_reference(in.labels, state, params);
      const ReferencePlacement cpu =
          place_reference(in.final_rgba8, in.layers, in.layer_count, labels, in.order, {}, in.size);
      check_placements(place_on_gpu(ctx, in, {}, {}, state, forces), cpu);
      for (size_t i = 0; i < in.labels.size(); ++i) {
        CAPTURE(i);
        CHECK(labels[i].hold == hold);
        CHECK(labels[i].held == state[i].drawn);
        const glm::vec2 expected = hold > 0.0f ? state[i].drawn : fresh.placements[i].position;
        CHECK(glm::all(
            glm::lessThanEqual(glm::abs(cpu.placements[i].position - expected), glm::vec2(0.5f))));
        // The reported cost is the position's own, the hold not included.
        CHECK(cpu.placements[i].cost < 1e3f);
      }
    }
  }

  // Hard mode's asymmetric clear zone: labels hidden last frame need `appear_padding_em` more room,
  // so in a crowded scene fewer of them appear than labels shown last frame keep their place.
  TEST_CASE_FIXTURE(test::GpuTest, "in_hard_mode_a_label_needs_more_room_to_appear_than_to_stay") {
    const Inputs in = disc_scene(12, 2.5f);
    PlacementSettings settings;
    settings.hard = true;
    const auto shown_count = [](const std::vector<gpu::PlacementGpu>& placements) {
      size_t n = 0;
      for (const auto& p : placements) n += p.shown == PLACEMENT_SHOWN;
      return n;
    };
    size_t shown[2] = {};
    for (const uint32_t flags : {LABEL_STATE_SEEN | LABEL_STATE_SHOWN, LABEL_STATE_SEEN}) {
      CAPTURE(flags);
      const std::vector<gpu::LabelStateGpu> state(in.labels.size(), {.flags = flags});
      const ForceSettings forces{.appear_padding_em = 1.0f};
      const gpu::ForcesParams params =
          forces_params(forces, kUnits, uint32_t(in.labels.size()), kFrameSeconds, true);
      const std::vector<gpu::LabelGpu> labels = previous_reference(in.labels, state, params);
      CHECK(labels[0].padding == (flags & LABEL_STATE_SHOWN ? 0.0f : kUnits.em));
      const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                     labels, in.order, settings, in.size);
      check_placements(place_on_gpu(ctx, in, settings, {}, state, forces), cpu);
      shown[flags & LABEL_STATE_SHOWN ? 0 : 1] = shown_count(cpu.placements);
    }
    MESSAGE("labels shown: staying " << shown[0] << ", appearing " << shown[1]);
    CHECK(shown[1] < shown[0]);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "bucket_width_changes_the_passes_not_the_positions") {
    // Twelve labels in a small scene, so later ones meet constraints and their best lies far
    // above their lowest tile bound: with a tiny width nearly every tile is left to the main
    // pass, with a huge one the speculative pass takes them all (and the main pass keeps or
    // re-evaluates each). The positions stay the reference's, with direct and indirect
    // dispatches.
    const Inputs in = disc_scene(12);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, {}, in.size);
    check_placements_across(ctx, in, cpu, {0.01f, 1.0f, 1e9f});
  }

  // The rounds on a crowded scene: the GPU's choices, the round each label was decided in and
  // the labels undecided before each round are the reference's exactly, over the same tables
  // (the reference searches every undecided label again each round, the GPU only those a newly
  // decided label constrains); no two labels decided in one round constrain each other, but for
  // the last round, which decides all that are left. Also with few rounds, with two priorities
  // (the order's second half waits for the first) and with few tiles searched (the labels that
  // find no position there search the rest).
  TEST_CASE_FIXTURE(test::GpuTest, "rounds_match_the_reference_and_commit_no_conflicting_pair") {
    Inputs in = disc_scene(0, 2.0f);
    for (uint32_t i = 0; i < 40; ++i) {
      const glm::vec2 anchor(float(60 + (i * 37) % 72), float(40 + (i * 23) % 64));
      in.labels.push_back(label(anchor, {float(14 + 2 * (i % 5)), 8.0f}, i % 2));
      in.order.push_back((i * 7) % 40);
    }
    // (rounds 0: two priorities; 1: two tiles searched)
    for (const uint32_t rounds : {128u, 3u, 0u, 1u}) {
      for (const bool hard : {false, true}) {
        const bool priorities = rounds == 0u, few_tiles = rounds == 1u;
        in.group_first.assign(priorities ? 40 : 0, 0u);
        for (uint32_t s = 20; s < in.group_first.size(); ++s) in.group_first[s] = 20;
        CAPTURE(rounds);
        CAPTURE(hard);
        PlacementSettings settings;
        settings.method = PlacementMethod::rounds;
        settings.tidy_rounds = 0;
        settings.rounds = priorities || few_tiles ? 128u : rounds;
        settings.round_tiles = few_tiles ? 2u : settings.round_tiles;
        settings.wide_search = few_tiles;
        settings.hard = hard;
        const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
        // (over the GPU's tables: its costs are then the same floats)
        const ReferenceRounds cpu = rounds_reference(in.labels, in.order, gpu.tables, settings,
                                                     in.size, in.layer_count, in.group_first);
        const auto n = uint32_t(in.labels.size());
        // (the same pixels everywhere; the same cost bits on a CPU device, whose float
        // arithmetic is the reference's: a GPU's square roots may differ in the last bits)
        const bool cpu_device = ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
        for (uint32_t i = 0; i < n; ++i) {
          CAPTURE(i);
          CHECK(uint32_t(gpu.results[i]) == uint32_t(cpu.results[i]));
          const float a = glm::uintBitsToFloat(uint32_t(gpu.results[i] >> 32));
          const float b = glm::uintBitsToFloat(uint32_t(cpu.results[i] >> 32));
          if (cpu_device || cpu.results[i] == PLACEMENT_NONE) CHECK(gpu.results[i] == cpu.results[i]);
          else CHECK(std::abs(a - b) <= 1e-5f * std::max(1.0f, std::abs(b)));
        }
        CHECK(std::vector(gpu.round_of.begin(), gpu.round_of.begin() + n) == cpu.round_of);
        const auto used = uint32_t(cpu.undecided.size());
        CHECK(std::vector(gpu.round_counts.begin(), gpu.round_counts.begin() + used) ==
              cpu.undecided);
        CHECK(gpu.round_counts[used] == 0u);
        MESSAGE(used << " rounds");
        CHECK(used >= 3u);  // (crowded: labels wait for others)
        size_t pairs = 0;
        for (uint32_t i = 0; i < n; ++i) {
          for (uint32_t j = i + 1; j < n; ++j) {
            if (gpu.round_of[i] != gpu.round_of[j] || gpu.round_of[i] + 1 == settings.rounds) {
              continue;
            }
            ++pairs;
            CAPTURE(i);
            CAPTURE(j);
            CHECK_FALSE(rounds_conflict_reference(in.labels[i], gpu.results[i], in.labels[j],
                                                  gpu.results[j], settings, in.size));
          }
        }
        CHECK(pairs > 10);
        if (priorities) {
          uint32_t first_done = 0, second_starts = ROUND_UNDECIDED;
          for (uint32_t s = 0; s < n; ++s) {
            const uint32_t r = gpu.round_of[in.order[s]];
            if (s < 20) first_done = std::max(first_done, r);
            else second_starts = std::min(second_starts, r);
          }
          CHECK(first_done < second_starts);
        }
      }
    }
  }

  // More labels than a workgroup culls at once (256) and than the tidy-up keeps in shared memory:
  // 300 small labels crowd the disc scene, so the last ones meet constraints from both chunks of
  // placed labels and anchors. The greedy positions and the tidied ones are the reference's,
  // dispatched directly and indirectly.
  TEST_CASE_FIXTURE(test::GpuTest, "more_labels_than_one_cull_chunk_match_the_reference") {
    Inputs in = disc_scene(0);
    for (uint32_t i = 0; i < 300; ++i) {
      const glm::vec2 anchor(float(14 + (i * 37) % 68), float(10 + (i * 23) % 52));
      in.labels.push_back(label(anchor, {float(6 + i % 5), 3.0f}, i % 2));
      in.order.push_back(i);
    }
    // (a round of the tidy-up with the labels' states read from the buffer; the dispatch only
    // matters to the greedy loop)
    for (const uint32_t rounds : {0u, 1u}) {
      CAPTURE(rounds);
      PlacementSettings settings;
      settings.tidy_rounds = rounds;
      const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                     in.labels, in.order, settings, in.size);
      for (const LabelDispatch dispatch : {LabelDispatch::direct, LabelDispatch::indirect}) {
        if (rounds > 0 && dispatch == LabelDispatch::indirect) continue;
        CAPTURE(int(dispatch));
        check_placements(place_on_gpu(ctx, in, settings, {.dispatch = dispatch}), cpu);
      }
      // (crowded: most labels past the first chunk pay for constraints)
      size_t constrained = 0;
      for (size_t i = 256; i < cpu.placements.size(); ++i) {
        constrained += cpu.placements[i].cost >= settings.weights.connector_shadow;
      }
      CHECK(constrained > 20);
    }
  }

  // Direct tidy-up rounds skip each block of kTidyBlockRounds past the first by conditional
  // rendering once the round before it applied nothing: the same rounds run and the same
  // positions as the reference's, whether blocks are skipped or run idle, and as the indirect
  // rounds (which skip each idle round instead).
  TEST_CASE_FIXTURE(test::GpuTest, "idle_tidy_up_blocks_are_skipped_exactly") {
    REQUIRE(ctx.conditional_rendering());  // (lavapipe and NVIDIA's driver have it)
    // (20 labels run 17 rounds: the block from round 16 runs, the next is skipped. More crowded
    // disc scenes end in cost ties that the GPU and the CPU break apart, summing in other orders.)
    for (const uint32_t labels : {6u, 20u}) {
      CAPTURE(labels);
      const Inputs in = disc_scene(labels, 2.5f);
      PlacementSettings settings;
      settings.tidy_rounds = 64;
      const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                     in.labels, in.order, settings, in.size);
      const GpuPlacement skipping =
          place_on_gpu(ctx, in, settings, {.dispatch = LabelDispatch::direct});
      const GpuPlacement running = place_on_gpu(
          ctx, in, settings, {.dispatch = LabelDispatch::direct, .skip_idle_blocks = false});
      const GpuPlacement indirect =
          place_on_gpu(ctx, in, settings, {.dispatch = LabelDispatch::indirect});
      const auto rounds = [&](const GpuPlacement& gpu) {
        return std::vector<uint32_t>(gpu.tidy_rounds.begin(),
                                     gpu.tidy_rounds.begin() + settings.tidy_rounds + 1);
      };
      for (const GpuPlacement* gpu : {&skipping, &running, &indirect}) {
        CAPTURE(gpu == &skipping ? "skipping" : gpu == &running ? "running" : "indirect");
        check_placements(*gpu, cpu);
        CHECK(rounds(*gpu) == rounds(skipping));
      }
      const auto run = uint32_t(std::count_if(skipping.tidy_rounds.begin(),
                                              skipping.tidy_rounds.begin() + settings.tidy_rounds,
                                              [](uint32_t changes) { return changes > 0; }));
      MESSAGE(labels << " labels: " << run << " tidy-up rounds run");
      // (the small scene ends in the first block; the crowded one runs past it)
      CHECK((labels == 6u ? run < kTidyBlockRounds : run > kTidyBlockRounds));
    }
  }

  TEST_CASE_FIXTURE(test::GpuTest, "classified_tiles_that_cannot_hold_the_best_are_left_out") {
    // Twelve labels crowd the disc: the later ones' lists hold tiles every candidate of which
    // lies in an earlier label's shadow, and their main passes must leave those out, with the
    // positions still the reference's.
    const Inputs in = disc_scene(12, 2.5f);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, {}, in.size);
    // (also direct with 3 workgroups for the passes' tiles, each taking many, and with two
    // invocations of a label's last workgroup taking its list, in chunks of eight entries, and
    // with 16 or 8 entries per classifying workgroup instead of 4)
    for (const PlacementLayout& layout :
         {PlacementLayout{.dispatch = LabelDispatch::direct},
          PlacementLayout{.dispatch = LabelDispatch::direct, .direct_groups = 3},
          PlacementLayout{.dispatch = LabelDispatch::indirect},
          PlacementLayout{.dispatch = LabelDispatch::indirect, .finish_lanes = 2},
          PlacementLayout{.dispatch = LabelDispatch::direct, .classify_tiles = 16},
          PlacementLayout{.dispatch = LabelDispatch::indirect, .classify_tiles = 8},
          PlacementLayout{.dispatch = LabelDispatch::direct, .pass_per_label = true},
          PlacementLayout{.dispatch = LabelDispatch::indirect, .pass_per_label = true}}) {
      CAPTURE(int(layout.dispatch));
      CAPTURE(layout.classify_tiles);
      CAPTURE(layout.direct_groups);
      CAPTURE(layout.finish_lanes);
      const GpuPlacement gpu = place_on_gpu(ctx, in, {}, layout);
      check_placements(gpu, cpu);
      uint32_t listed = 0, taken = 0;
      for (size_t s = 0; s < in.order.size(); ++s) {
        const gpu::PlacementBucketsGpu& b = gpu.buckets[s];
        uint32_t all = 0;
        for (const uint32_t c : b.counts) all += c;
        CHECK(b.main == b.counts[0] + b.rest);
        CHECK(b.rest <= all - b.counts[0]);
        listed += all - b.counts[0];
        taken += b.rest;
      }
      MESSAGE("main pass tiles past bucket 0: " << taken << " of " << listed);
      CHECK(taken * 2 < listed);
    }
  }

  TEST_CASE_FIXTURE(test::GpuTest, "a_speculative_winner_the_label_before_takes_is_not_kept") {
    // Label 1 is evaluated while label 0 is still being placed, without label 0's constraints.
    // Their anchors are neighbours, so where label 1 would go alone is where label 0 goes (or in
    // its shadow): the main pass must move it, to where the sequential reference puts it.
    Inputs in = disc_scene(2);
    in.labels[0] = label({44.0f, 30.0f}, {20.0f, 8.0f}, 0);
    in.labels[1] = label({46.0f, 31.0f}, {20.0f, 8.0f}, 0);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, {}, in.size);
    const std::vector<uint32_t> only_1{1};
    const ReferencePlacement alone =
        place_reference(in.final_rgba8, in.layers, in.layer_count, in.labels, only_1, {}, in.size);
    REQUIRE(alone.placements[1].shown == PLACEMENT_SHOWN);
    CHECK(glm::length(alone.placements[1].position - cpu.placements[1].position) > 1.0f);
    check_placements_across(ctx, in, cpu, {1.0f, 1e9f});  // (1e9: bucket 0 holds every tile)
  }

  TEST_CASE_FIXTURE(test::GpuTest, "one_layer_uses_eq_3_4_and_still_matches") {
    Inputs in = disc_scene(4);
    const size_t pixels = size_t{in.size.width} * in.size.height;
    for (size_t p = 0; p < pixels; ++p) {
      glm::vec4 v = in.layers[p] + (1.0f - in.layers[p].a) * in.layers[pixels + p];
      for (int ch = 0; ch < 4; ++ch) v[ch] = glm::unpackHalf1x16(glm::packHalf1x16(v[ch]));
      in.layers[p] = v;
    }
    in.layers.resize(pixels);
    in.layer_count = 1;
    for (auto& l : in.labels) l.layer = 0;
    const GpuPlacement gpu = place_on_gpu(ctx, in, {});
    const ReferencePlacement cpu =
        place_reference(in.final_rgba8, in.layers, 1, in.labels, in.order, {}, in.size);
    check_values(gpu.costs, cpu.costs, 1e-3f, false, "integral costs");
    check_placements(gpu, cpu);
  }

  TEST_CASE_FIXTURE(test::GpuTest,
                    "constraint_image_marks_the_shadow_of_a_placed_box_and_the_anchors") {
    // Label 0 has the screen to itself; label 1's constraints then hold its shadow.
    Inputs in = disc_scene(2);
    in.labels[0] = label({20.0f, 36.0f}, {16.0f, 8.0f}, 0);
    in.labels[1] = label({70.0f, 36.0f}, {10.0f, 6.0f}, 0);
    PlacementSettings settings;
    settings.method = PlacementMethod::sequential;  // (its constraint image)
    settings.write_constraints = true;
    settings.margin_em = 0.0f;
    const GpuPlacement gpu = place_on_gpu(ctx, in, settings);
    const ReferencePlacement cpu = place_reference(in.final_rgba8, in.layers, in.layer_count,
                                                   in.labels, in.order, settings, in.size);
    CHECK(gpu.constraints == cpu.constraints);
    const glm::vec2 placed = gpu.placements[0].position;
    const auto bits_at = [&](glm::vec2 centre) {
      // Candidate pixel whose box (10x6) is centred at `centre`.
      const glm::uvec2 p(uint32_t(centre.x - 5.0f + 5.0f), uint32_t(centre.y - 3.0f + 3.0f));
      return gpu.constraints[p.y * in.size.width + p.x];
    };
    // On the far side of label 0 as seen from label 1's anchor: its shadow.
    const glm::vec2 behind = placed + glm::normalize(placed - in.labels[1].anchor) * 14.0f;
    if (behind.x >= 5.0f && behind.y >= 3.0f) CHECK((bits_at(behind) & CONSTRAINT_LABEL) != 0u);
    // Covering label 0's anchor, and covering its own anchor.
    CHECK((bits_at(in.labels[0].anchor) & CONSTRAINT_ANCHOR) != 0u);
    CHECK((bits_at(in.labels[1].anchor) & CONSTRAINT_ANCHOR) != 0u);
    // Far from everything, on the other side of the new anchor: free.
    CHECK(bits_at({88.0f, 10.0f}) == 0u);
  }

  TEST_CASE_FIXTURE(test::GpuTest, "hard_constraints_hide_a_label_that_cannot_fit") {
    Inputs in = disc_scene(2);
    in.size = {48, 24};
    in.final_rgba8.assign(size_t(48) * 24 * 4, 0);
    in.layers.assign(size_t(48) * 24 * 2, glm::vec4(0.0f));
    // With a 6-pixel margin, label 1's box covers one of the two anchors wherever it goes.
    in.labels[0] = label({8.0f, 12.0f}, {10.0f, 6.0f}, 0);
    in.labels[1] = label({40.0f, 12.0f}, {30.0f, 10.0f}, 0);
    PlacementSettings hard;
    hard.hard = true;
    const GpuPlacement gpu = place_on_gpu(ctx, in, hard);
    CHECK(gpu.placements[0].shown == PLACEMENT_SHOWN);
    CHECK(gpu.placements[1].shown == PLACEMENT_HIDDEN);
    const GpuPlacement soft = place_on_gpu(ctx, in, {});
    CHECK(soft.placements[1].shown == PLACEMENT_SHOWN);
    CHECK(soft.placements[1].cost >= 100.0f);  // it violates a constraint
  }
}

}  // namespace strata
