// Forces (eq. 3.6-3.8): the GPU pass against its CPU reference, and how a label moves.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <random>

#include "engine/core/error.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "gpu_fixture.h"
#include "passes/label_forces.h"

namespace strata {
namespace {

// An image 1024 px square (a pixel is 1/1024 of its width, exact in a float) and 14 px text.
constexpr LabelUnits kUnits{1024.0f, 14.0f, 1024.0f};
// The forces alone, each label on its own (what the tests of their arithmetic follow).
constexpr ForceSettings kAlone{.keep_apart = false};
constexpr float widths(float pixels) {
  return pixels / kUnits.width;
}

gpu::LabelGpu label_at(glm::vec2 anchor, bool enabled = true) {
  gpu::LabelGpu l{};
  l.anchor = anchor;
  l.size = {60.0f, 16.0f};
  l.flags = enabled ? LABEL_ENABLED : 0u;
  return l;
}

gpu::PlacementGpu target_at(glm::vec2 position, bool shown = true) {
  return {position, 1.0f, shown ? PLACEMENT_SHOWN : PLACEMENT_HIDDEN};
}

gpu::LabelStateGpu placed_at(glm::vec2 position) {
  gpu::LabelStateGpu s{};
  s.position = position;
  s.flags = LABEL_STATE_PLACED;
  return s;
}

// One label followed over frames of `seconds` toward a fixed target, on its own (the image's edge
// not in the way): the distances, frame by frame.
std::vector<float> approach(ForceSettings settings, glm::vec2 start, glm::vec2 goal, int frames,
                            double seconds = 1.0 / 30.0) {
  settings.keep_apart = false;
  const gpu::ForcesParams params = forces_params(settings, kUnits, 1, seconds);
  std::vector<gpu::LabelStateGpu> state{placed_at(start)};
  std::vector<float> distances;
  for (int f = 0; f < frames; ++f) {
    const auto drawn = forces_reference({label_at({0.0f, 0.0f})}, {target_at(goal)}, state, params);
    distances.push_back(glm::length(goal - drawn[0].position));
  }
  return distances;
}

template <typename T>
std::vector<T> as(const std::vector<std::byte>& bytes) {
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

// A camera path as the forces see it, at an image `width` wide and `fps` frames a second: eight
// anchors turning a quarter turn a second about the image's centre, each label's target an offset
// from its anchor that the placement changes every 4 s, long enough for the labels to arrive (the
// same offsets in widths at every size). Frame 0 is a still. Returns each frame's offsets of the
// drawn boxes from their anchors, in widths: `run` is one frame of the forces (CPU reference or
// GPU).
constexpr int kPathLabels = 8;
constexpr double kPathSeconds = 12.0;
using ForcesFrame = std::function<std::vector<gpu::PlacementGpu>(
    const std::vector<gpu::LabelGpu>&, const std::vector<gpu::PlacementGpu>&, LabelUnits, double)>;

std::vector<std::vector<glm::vec2>> offsets_along_path(float width, int fps,
                                                       const ForcesFrame& run) {
  std::vector<std::vector<glm::vec2>> out;
  const int frames = int(kPathSeconds * fps);
  for (int f = 0; f <= frames; ++f) {
    const double t = double(f) / fps;
    const int change = f / (4 * fps);  // the placement's new targets every 4 s
    std::vector<gpu::LabelGpu> labels;
    std::vector<gpu::PlacementGpu> targets;
    for (int i = 0; i < kPathLabels; ++i) {
      const double angle = 0.785 * i + 1.5707963 * t;
      const glm::vec2 anchor =
          width * glm::vec2(0.5 + 0.3 * std::cos(angle), 0.5 + 0.3 * std::sin(angle));
      const double turn = 2.3 * i + 1.9 * change;  // the target's direction
      const float reach = 0.04f + 0.01f * float((i + change) % 7);
      const glm::vec2 offset = width * reach * glm::vec2(std::cos(turn), std::sin(turn));
      labels.push_back(label_at(anchor));
      targets.push_back(target_at(anchor + offset));
    }
    const auto drawn = run(labels, targets, {width, 14.0f, width}, f == 0 ? 0.0 : 1.0 / fps);
    std::vector<glm::vec2> offsets;
    for (int i = 0; i < kPathLabels; ++i) {
      offsets.push_back((drawn[size_t(i)].position - labels[size_t(i)].anchor) / width);
    }
    out.push_back(offsets);
  }
  return out;
}

ForcesFrame reference_frames(const ForceSettings& settings) {
  auto state = std::make_shared<std::vector<gpu::LabelStateGpu>>(kPathLabels);
  return [settings, state](const std::vector<gpu::LabelGpu>& labels,
                           const std::vector<gpu::PlacementGpu>& targets, LabelUnits units,
                           double seconds) {
    return forces_reference(labels, targets, *state,
                            forces_params(settings, units, kPathLabels, seconds));
  };
}

// The motion of the labels relative to their anchors in widths per second, measured over the
// same instants at any frame rate (every 1/12 s): the mean and the 95th percentile.
std::pair<double, double> motion_per_second(const std::vector<std::vector<glm::vec2>>& offsets,
                                            int fps) {
  const int every = fps / 12;
  std::vector<double> speeds;
  for (size_t f = size_t(every); f < offsets.size(); f += size_t(every)) {
    for (int i = 0; i < kPathLabels; ++i) {
      speeds.push_back(12.0 * glm::length(offsets[f][size_t(i)] - offsets[f - every][size_t(i)]));
    }
  }
  std::sort(speeds.begin(), speeds.end());
  double mean = 0.0;
  for (const double s : speeds) mean += s / double(speeds.size());
  return {mean, speeds[size_t(0.95 * double(speeds.size() - 1))]};
}

// The forces pass on the GPU, its labels and targets uploaded for each frame.
class GpuForces {
 public:
  GpuForces(Context& ctx, uint32_t count)
      : ctx_(ctx),
        labels_(ctx, count * sizeof(gpu::LabelGpu), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                MemoryKind::device_local),
        targets_(ctx, count * sizeof(gpu::PlacementGpu), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                 MemoryKind::device_local),
        order_(ctx, count * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
               MemoryKind::device_local),
        forces_(ctx, count) {
    graph::Graph g;
    const graph::ResourceId state = forces_.import_state(g);
    const auto imported = [&g](const char* name, const Buffer& buffer) {
      return g.import_buffer(name, {.buffer = buffer.handle(), .has_content = true});
    };
    drawn_ = forces_
                 .add_to(g, {.labels = imported("labels", labels_),
                             .targets = imported("targets", targets_),
                             .state = state,
                             .order = imported("order", order_)})
                 .drawn;
    runner_ = std::make_unique<graph::GraphRunner>(ctx, std::move(g));
    runner_->set_viewport({512, 512});
  }

  // One frame: where the labels are drawn. `order`: the placement's insertion order (none: the
  // labels' own).
  std::vector<gpu::PlacementGpu> frame(const std::vector<gpu::LabelGpu>& labels,
                                       const std::vector<gpu::PlacementGpu>& targets,
                                       const ForceSettings& settings, LabelUnits units,
                                       double seconds, const std::vector<uint32_t>& order = {},
                                       std::span<const glm::uvec4> keep_out = {}) {
    upload(ctx_, labels_, as_bytes(labels));
    upload(ctx_, targets_, as_bytes(targets));
    if (!order.empty()) upload(ctx_, order_, as_bytes(order));
    forces_.set_frame(settings, units, seconds, false, uint32_t(order.size()));
    forces_.set_keep_out(keep_out);
    runner_->run_now();
    return as<gpu::PlacementGpu>(runner_->download_buffer(drawn_));
  }
  std::vector<gpu::LabelStateGpu> state() const { return forces_.state(); }

 private:
  Context& ctx_;
  Buffer labels_, targets_, order_;
  LabelForces forces_;
  graph::ResourceId drawn_{};
  std::unique_ptr<graph::GraphRunner> runner_;
};

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("a_frame_is_split_into_short_steps_that_never_move_a_label_past_epsilon") {
    const ForceSettings s{.speed_widths = widths(6000.0f), .epsilon_widths = widths(24.0f)};
    const gpu::ForcesParams p = forces_params(s, kUnits, 1, 1.0 / 30.0);
    CHECK(p.speed == 6000.0f);  // widths times the image's width
    CHECK(p.epsilon == 24.0f);
    CHECK(p.steps == 9);  // 200 px in a frame: more steps than the 4 of 1/120 s
    CHECK(p.step_seconds * p.speed <= p.epsilon);
    CHECK(forces_params({}, kUnits, 1, 1.0 / 30.0).steps == 4);  // 1/120 s at most
    CHECK(forces_params({}, kUnits, 1, 1.0 / 12.0).steps == 10);
    CHECK(forces_params({}, kUnits, 1, 0.0).steps == 1);
    CHECK_THROWS_AS(forces_params({.speed_widths = 0.0f}, kUnits, 1, 0.1), Error);
    CHECK_THROWS_AS(forces_params({}, {0.0f, 14.0f, 1024.0f}, 1, 0.1), Error);
    CHECK_THROWS_AS(forces_params({}, {1024.0f, 14.0f}, 1, 0.1), Error);  // no height to keep in
    CHECK(forces_params({}, kUnits, 1, 0.1).keep_apart == 1u);
    CHECK(forces_params(kAlone, kUnits, 1, 0.1).keep_apart == 0u);
  }

  TEST_CASE("speeds_and_distances_are_shares_of_the_width_paddings_of_the_text_size") {
    const ForceSettings s{.appear_padding_em = 0.5f};
    for (const float width : {128.0f, 1920.0f}) {
      const gpu::ForcesParams p = forces_params(s, {width, 20.0f, width}, 1, 1.0 / 30.0, true);
      CHECK(p.speed == doctest::Approx(s.speed_widths * width));
      CHECK(p.epsilon == doctest::Approx(s.epsilon_widths * width));
      CHECK(p.snap == s.snap);  // a sub-pixel rounding: pixels at any size
      CHECK(p.appear_padding == 10.0f);
      CHECK(p.acceleration == doctest::Approx(p.speed / s.ease_in_seconds));
    }
    // The defaults are what were pixels at 1024 px wide and a 14 px font.
    const gpu::ForcesParams d = forces_params({}, kUnits, 1, 1.0 / 30.0, true);
    CHECK(d.speed == doctest::Approx(90.0f).epsilon(0.01));
    CHECK(d.epsilon == doctest::Approx(24.0f).epsilon(0.01));
    CHECK(d.appear_padding == 8.0f);
  }

  TEST_CASE("a_label_eases_in_to_full_speed_over_the_ease_in_time") {
    // 600 px/s reached in 0.2 s: 3000 px/s per second, 1/120 s steps.
    const ForceSettings s{.speed_widths = widths(600.0f), .ease_in_seconds = 0.2f};
    const std::vector<float> d = approach(s, {0.0f, 0.0f}, {500.0f, 0.0f}, 14, 1.0 / 60.0);
    std::vector<float> moved{500.0f - d[0]};
    for (size_t f = 1; f < d.size(); ++f) moved.push_back(d[f - 1] - d[f]);
    for (size_t f = 1; f < moved.size(); ++f) CHECK(moved[f] >= moved[f - 1]);
    CHECK(moved[0] ==
          doctest::Approx(3000.0 * (1.0 / 120.0) * (1.0 / 120.0) * 3.0));  // 1 + 2 steps
    CHECK(moved[11] < 10.0f);
    CHECK(moved[12] == doctest::Approx(10.0f));  // full speed after 0.2 s: 10 px a frame
    CHECK(moved[13] == doctest::Approx(10.0f));
  }

  // The same camera path at 128 and 512 px wide and at 12 and 60 frames a second moves labels
  // the same share of the image per second. The forces scale with the width, and the sub-steps
  // (1/120 s) are the same at both rates, so what differs is: the snap, half a pixel at any size,
  // which ends an approach up to 0.5 / 128 of the width early at 128 px; and a frame's lead: a
  // frame moves its labels over the time up to it toward the target of its own time, so at 12 fps
  // a label starts toward a new target 1/12 - 1/60 s before it does at 60 fps (at full speed:
  // 0.6% of the width), and arrives as much earlier. The paths' lengths, and so the mean motion,
  // differ by the snap's half pixel per approach at most (two per label); the 95th percentile
  // (full speed: most of the motion) by rounding.
  TEST_CASE("labels_move_the_same_share_of_the_image_per_second_at_any_size_and_frame_rate") {
    const ForceSettings settings = kAlone;
    const auto base = offsets_along_path(512.0f, 60, reference_frames(settings));
    const auto [base_mean, base_p95] = motion_per_second(base, 60);
    MESSAGE("512 px, 60 fps: mean " << base_mean << ", p95 " << base_p95 << " widths/s");
    CHECK(base_mean > 0.01);                            // the labels do move ...
    CHECK(base_p95 <= settings.speed_widths * 1.0001);  // ... never faster than the forces allow
    for (const float width : {128.0f, 512.0f}) {
      for (const int fps : {12, 60}) {
        CAPTURE(width);
        CAPTURE(fps);
        const auto offsets = offsets_along_path(width, fps, reference_frames(settings));
        float largest = 0.0f;  // the largest difference in position, in widths
        for (size_t j = 0; j < base.size(); j += 5) {
          for (int i = 0; i < kPathLabels; ++i) {
            const glm::vec2 d = offsets[j * size_t(fps) / 60][size_t(i)] - base[j][size_t(i)];
            largest = std::max(largest, glm::length(d));
          }
        }
        const double lead = settings.speed_widths * (1.0 / 12.0 - 1.0 / 60.0);
        CHECK(largest <= 0.5 / 128.0 + lead + 1e-5);
        const auto [mean, p95] = motion_per_second(offsets, fps);
        MESSAGE(width << " px, " << fps << " fps: mean " << mean << ", p95 " << p95
                      << " widths/s, positions within " << largest << " widths");
        CHECK(std::abs(mean - base_mean) <= 2.0 * (0.5 / 128.0) / kPathSeconds);
        CHECK(std::abs(p95 - base_p95) <= 1e-4);
      }
    }
  }

  TEST_CASE("a_label_converges_to_a_still_target_without_overshoot_and_stays") {
    const glm::vec2 start{100.0f, 100.0f}, goal{400.0f, 500.0f};  // 500 px apart
    const ForceSettings s{
        .speed_widths = widths(600.0f), .epsilon_widths = widths(24.0f), .ease_in_seconds = 0.0f};
    const std::vector<float> d = approach(s, start, goal, 60);
    for (size_t f = 1; f < d.size(); ++f) CHECK(d[f] <= d[f - 1]);
    // At 600 px/s the unit force covers 480 px in 24 frames; then the attenuated tail and the snap.
    CHECK(d[23] == doctest::Approx(20.0f).epsilon(1e-3));
    size_t arrived = 0;
    while (arrived < d.size() && d[arrived] > 0.0f) ++arrived;
    CHECK(arrived < 40);
    for (size_t f = arrived; f < d.size(); ++f) CHECK(d[f] == 0.0f);
  }

  TEST_CASE("within_epsilon_the_force_shrinks_with_the_distance") {
    // 12 px away with epsilon 24: a step of 20 px at full force would overshoot; the attenuated
    // force moves it 12 * 20 / 24 = 10 px.
    const ForceSettings s{
        .speed_widths = widths(2400.0f), .epsilon_widths = widths(24.0f), .ease_in_seconds = 0.0f};
    const std::vector<float> d = approach(s, {0.0f, 0.0f}, {12.0f, 0.0f}, 1, 1.0 / 120.0);
    CHECK(d[0] == doctest::Approx(2.0f).epsilon(1e-5));
  }

  TEST_CASE("anchored_labels_move_rigidly_with_their_anchor_screen_labels_lag") {
    std::vector<gpu::LabelStateGpu> anchored(1), screen(1);
    const gpu::ForcesParams a = forces_params({.anchor_relative = true}, kUnits, 1, 1.0 / 30.0);
    const gpu::ForcesParams s = forces_params({.anchor_relative = false}, kUnits, 1, 1.0 / 30.0);
    const glm::vec2 offset{80.0f, -40.0f};
    for (int f = 0; f < 20; ++f) {
      const glm::vec2 anchor{100.0f + 15.0f * float(f), 300.0f};  // 450 px/s to the right
      const std::vector<gpu::LabelGpu> labels{label_at(anchor)};
      const std::vector<gpu::PlacementGpu> targets{target_at(anchor + offset)};
      CHECK(forces_reference(labels, targets, anchored, a)[0].position == anchor + offset);
      const glm::vec2 lag = forces_reference(labels, targets, screen, s)[0].position - anchor;
      if (f > 0) CHECK(glm::length(lag - offset) > 1.0f);
    }
  }

  TEST_CASE("hidden_and_disabled_labels_keep_their_drawn_position") {
    std::vector<gpu::LabelStateGpu> state{placed_at({10.0f, 20.0f}), placed_at({30.0f, 40.0f})};
    const gpu::ForcesParams p = forces_params({.anchor_relative = false}, kUnits, 2, 1.0 / 30.0);
    const auto drawn =
        forces_reference({label_at({0.0f, 0.0f}), label_at({0.0f, 0.0f}, false)},
                         {target_at({500.0f, 500.0f}, false), target_at({500.0f, 0.0f})}, state, p);
    CHECK(state[0].position == glm::vec2(10.0f, 20.0f));
    CHECK(state[1].position == glm::vec2(30.0f, 40.0f));
    CHECK(drawn[0].shown == PLACEMENT_HIDDEN);
  }

  TEST_CASE("labels_fade_out_where_they_were_and_fade_in_over_the_fade_time") {
    // 0.3 s at 30 frames per second: 1/9 of the way each frame.
    const ForceSettings settings{
        .anchor_relative = true, .fade_seconds = 0.3f, .min_hidden_seconds = 0.0f};
    const gpu::ForcesParams p = forces_params(settings, kUnits, 1, 1.0 / 30.0);
    CHECK(p.fade == doctest::Approx(1.0f / 9.0f));
    CHECK(forces_params(settings, kUnits, 1, 0.0).fade == 1.0f);  // a still: at once
    std::vector<gpu::LabelStateGpu> state(1);
    const glm::vec2 offset{50.0f, -20.0f};
    // Shown in a still: fully drawn at once.
    glm::vec2 anchor{100.0f, 100.0f};
    auto drawn = forces_reference({label_at(anchor)}, {target_at(anchor + offset)}, state,
                                  forces_params(settings, kUnits, 1, 0.0));
    CHECK(drawn[0].opacity == 1.0f);
    // Hidden by the placement: fades out over 9 frames, drawn at its offset from the moving anchor.
    for (int f = 1; f <= 10; ++f) {
      CAPTURE(f);
      anchor.x += 3.0f;
      drawn = forces_reference({label_at(anchor)}, {target_at(anchor, false)}, state, p);
      const float expected = std::max(0.0f, 1.0f - float(f) / 9.0f);
      CHECK(drawn[0].opacity == doctest::Approx(expected).epsilon(1e-5));
      CHECK(drawn[0].shown == (f < 9 ? PLACEMENT_SHOWN : PLACEMENT_HIDDEN));
      if (f < 9) CHECK(drawn[0].position == anchor + offset);
    }
    // Shown again: fades in, never more than 1.
    for (int f = 1; f <= 10; ++f) {
      drawn = forces_reference({label_at(anchor)}, {target_at(anchor + offset)}, state, p);
      CHECK(drawn[0].opacity == doctest::Approx(std::min(1.0f, float(f) / 9.0f)).epsilon(1e-5));
    }
  }

  TEST_CASE("a_kept_target_keeps_its_exact_offset_a_new_target_is_the_placements") {
    // The placement rounds to its candidate pixels; a label it keeps on the held position keeps
    // the exact offset it had, so it does not drift by that rounding from frame to frame.
    const gpu::ForcesParams p = forces_params({.anchor_relative = true}, kUnits, 1, 1.0 / 30.0);
    gpu::LabelStateGpu s{};
    s.position = s.target = {40.3f, -12.7f};
    s.flags = LABEL_STATE_PLACED | LABEL_STATE_SHOWN | LABEL_STATE_SEEN;
    s.cost = 10.0f;
    std::vector<gpu::LabelStateGpu> state{s};
    const glm::vec2 anchor{200.25f, 150.5f};
    const gpu::LabelGpu held = previous_reference({label_at(anchor)}, state, p)[0];
    CHECK(held.held == anchor + s.target);
    CHECK(held.hold == doctest::Approx(p.hold_cost + p.hold_share * 10.0f));
    // Kept: the placement's pixel is within half a pixel of the held position.
    auto drawn = forces_reference({held}, {target_at(glm::round(held.held))}, state, p);
    CHECK(state[0].target == s.target);
    CHECK(drawn[0].position == anchor + s.target);
    // Moved elsewhere: the new target is the placement's.
    const glm::vec2 elsewhere = anchor + glm::vec2(-80.0f, 30.0f);
    forces_reference({held}, {target_at(elsewhere)}, state, p);
    CHECK(state[0].target == elsewhere - anchor);
  }

  // Keeping apart (shaders/shared/keep_apart.h): a label's way through another's box is taken; it
  // waits, then fades out where it is and fades in at its target. No frame has two apparent boxes
  // overlapping.
  TEST_CASE("a_label_whose_way_is_taken_waits_then_fades_out_and_appears_at_its_target") {
    const ForceSettings settings{
        .fade_seconds = 0.3f, .wait_seconds = 0.4f, .min_hidden_seconds = 0.2f};
    const gpu::ForcesParams still = forces_params(settings, kUnits, 2, 0.0, false, 2);
    const gpu::ForcesParams p = forces_params(settings, kUnits, 2, 1.0 / 30.0, false, 2);
    // Label 0 (first in the order) sits still at (500, 300); label 1 starts at (400, 300) and
    // heads for (600, 300), through label 0's box (60 x 16).
    const std::vector<gpu::LabelGpu> labels{label_at({500.0f, 300.0f}), label_at({400.0f, 300.0f})};
    std::vector<gpu::LabelStateGpu> state(2);
    forces_reference(labels, {target_at({500.0f, 300.0f}), target_at({400.0f, 300.0f})}, state,
                     still, {0, 1});
    const std::vector<gpu::PlacementGpu> targets{target_at({500.0f, 300.0f}),
                                                 target_at({600.0f, 300.0f})};
    int waited = 0, faded = -1, appeared = -1;
    for (int f = 1; f <= 75; ++f) {
      CAPTURE(f);
      const auto drawn = forces_reference(labels, targets, state, p, {0, 1});
      CHECK(drawn[0].position == glm::vec2(500.0f, 300.0f));
      CHECK(drawn[0].opacity == 1.0f);
      const glm::vec4 a = gpu::box_around(drawn[0].position, labels[0].size);
      const glm::vec4 b = gpu::box_around(drawn[1].position, labels[1].size);
      if (drawn[1].opacity > 0.0f) CHECK_FALSE(gpu::boxes_clash(a, b, p.clearance));
      if (faded < 0 && drawn[1].position.x < 440.0f && drawn[1].position.x > 400.0f) ++waited;
      if (faded < 0 && drawn[1].opacity < 1.0f) faded = f;
      if (appeared < 0 && drawn[1].position.x == 600.0f && drawn[1].opacity > 0.0f) appeared = f;
    }
    // It moved up to the other's box (30 px apart at most), waited 0.4 s (12 frames), faded out
    // over 0.3 s (9 frames), stayed hidden 0.2 s (6 frames, 7 where the sum of the frames'
    // seconds rounds below) and came in at its target.
    CHECK(waited >= 12);
    CHECK(faded > 12);
    CHECK(appeared >= faded + 9 + 6);
    CHECK(appeared <= faded + 9 + 7);
    CHECK(state[1].opacity == 1.0f);
    CHECK(state[1].position == glm::vec2(200.0f, 0.0f));  // its target's offset
  }

  TEST_CASE("boxes_brought_together_by_their_anchors_the_one_later_in_the_order_goes_at_once") {
    const gpu::ForcesParams still = forces_params({}, kUnits, 2, 0.0, false, 2);
    const gpu::ForcesParams p = forces_params({}, kUnits, 2, 1.0 / 30.0, false, 2);
    // Two labels on their targets, 100 px apart; their anchors close in at 300 px/s. The order
    // puts label 1 first: label 0 goes when the boxes would touch.
    const std::vector<uint32_t> order{1, 0};
    std::vector<gpu::LabelStateGpu> state(2);
    bool gone = false;
    for (int f = 0; f < 30; ++f) {
      CAPTURE(f);
      const float x = 400.0f + 5.0f * float(f);
      const std::vector<gpu::LabelGpu> labels{label_at({x, 300.0f}), label_at({600.0f, 300.0f})};
      const std::vector<gpu::PlacementGpu> targets{target_at({x, 280.0f}),
                                                   target_at({600.0f, 280.0f})};
      const auto drawn = forces_reference(labels, targets, state, f == 0 ? still : p, order);
      CHECK(drawn[1].opacity == 1.0f);
      const glm::vec4 a = gpu::box_around(drawn[0].position, labels[0].size);
      const glm::vec4 b = gpu::box_around(drawn[1].position, labels[1].size);
      if (gpu::boxes_clash(a, b, p.clearance)) CHECK(drawn[0].opacity == 0.0f);
      gone = gone || drawn[0].opacity == 0.0f;
    }
    CHECK(gone);
  }

  TEST_CASE("a_box_leaving_the_image_goes_and_comes_back_only_inside_it") {
    const gpu::ForcesParams still = forces_params({}, kUnits, 1, 0.0, false, 1);
    const gpu::ForcesParams p = forces_params({}, kUnits, 1, 1.0 / 30.0, false, 1);
    std::vector<gpu::LabelStateGpu> state(1);
    const glm::vec2 offset{0.0f, -20.0f};
    for (int f = 0; f < 40; ++f) {
      CAPTURE(f);
      // The anchor runs out of the image's right edge and back in.
      const float x = f < 20 ? 960.0f + 5.0f * float(f) : 1060.0f - 5.0f * float(f - 20);
      const auto drawn = forces_reference({label_at({x, 300.0f})}, {target_at({x, 280.0f})}, state,
                                          f == 0 ? still : p, {0});
      const glm::vec4 box = gpu::box_around(drawn[0].position, {60.0f, 16.0f});
      if (drawn[0].opacity > 0.0f) CHECK(gpu::box_inside(box, p));
      if (f == 19) CHECK(drawn[0].opacity == 0.0f);
      if (f == 39) CHECK(drawn[0].opacity > 0.0f);  // back in, fading in
    }
  }

  // Many labels on random paths: no two drawn boxes ever overlap, none is cut, none reaches over
  // a keep-out rectangle (a title, a legend), and the forces' speed still bounds every move of a
  // drawn label.
  TEST_CASE("kept_apart_no_drawn_boxes_overlap_or_leave_the_image_in_any_frame") {
    for (const bool margins : {false, true}) {
      CAPTURE(margins);
      const std::vector<glm::uvec4> keep_out =
          margins ? std::vector<glm::uvec4>{{0u, 0u, 1024u, 120u}, {700u, 800u, 1024u, 1024u}}
                  : std::vector<glm::uvec4>{};
      const uint32_t count = 40;
      std::mt19937 rng(5);
      std::uniform_real_distribution<float> unit(0.0f, 1.0f);
      std::vector<glm::vec2> start(count), velocity(count), offset(count);
      for (uint32_t i = 0; i < count; ++i) {
        start[i] = {100.0f + 824.0f * unit(rng), 100.0f + 824.0f * unit(rng)};
        velocity[i] = {200.0f * unit(rng) - 100.0f, 200.0f * unit(rng) - 100.0f};
        offset[i] = {160.0f * unit(rng) - 80.0f, 160.0f * unit(rng) - 80.0f};
      }
      std::vector<uint32_t> order(count);
      for (uint32_t i = 0; i < count; ++i) order[i] = (i * 7) % count;
      std::vector<gpu::LabelStateGpu> state(count);
      gpu::ForcesParams p = forces_params({}, kUnits, count, 1.0 / 30.0, false, count);
      gpu::ForcesParams still = forces_params({}, kUnits, count, 0.0, false, count);
      set_keep_out(p, keep_out);
      set_keep_out(still, keep_out);
      std::vector<gpu::PlacementGpu> last;
      int shown = 0;
      for (int f = 0; f < 120; ++f) {
        const float t = float(f) / 30.0f;
        std::vector<gpu::LabelGpu> labels;
        std::vector<gpu::PlacementGpu> targets;
        for (uint32_t i = 0; i < count; ++i) {
          labels.push_back(label_at(start[i] + t * velocity[i]));
          // a new offset every second
          const float turn = float(f / 30) * 1.3f + float(i);
          targets.push_back(target_at(labels.back().anchor + offset[i] +
                                      40.0f * glm::vec2(std::cos(turn), std::sin(turn))));
        }
        const auto drawn = forces_reference(labels, targets, state, f == 0 ? still : p, order);
        for (uint32_t i = 0; i < count && f > 0; ++i) {
          if (!(drawn[i].opacity > 0.0f)) continue;
          ++shown;
          const glm::vec4 a = gpu::box_around(drawn[i].position, labels[i].size);
          CHECK(gpu::box_inside(a, p));
          for (const glm::uvec4& k : keep_out) CHECK_FALSE(gpu::boxes_clash(a, glm::vec4(k), 0.0f));
          for (uint32_t j = i + 1; j < count; ++j) {
            if (drawn[j].opacity > 0.0f) {
              const glm::vec4 b = gpu::box_around(drawn[j].position, labels[j].size);
              CHECK_FALSE(gpu::boxes_clash(a, b, p.clearance));
            }
          }
          // Relative to its anchor, a label drawn in both frames moves at most the forces' speed,
          // and as much again where the image's edge pushes it in.
          if (last[i].opacity > 0.0f && drawn[i].opacity < 1.0f && last[i].opacity < 1.0f) continue;
          if (last[i].opacity > 0.0f) {
            const glm::vec2 moved =
                (drawn[i].position - labels[i].anchor) -
                (last[i].position - (start[i] + (t - 1.0f / 30.0f) * velocity[i]));
            CHECK(glm::length(moved) <= 2.0f * p.speed / 30.0f + 1e-3f);
          }
        }
        last = drawn;
      }
      MESSAGE("drawn labels per frame: " << double(shown) / 119.0);
      CHECK(shown > 119 * int(count) / (margins ? 3 : 2));  // most labels stay drawn
    }
  }
}

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "forces_pass_matches_cpu_reference_over_frames") {
    const uint32_t count = 300;  // more labels than the workgroup has invocations
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> pixel(0.0f, 1024.0f);
    std::vector<gpu::LabelGpu> labels(count);
    std::vector<gpu::PlacementGpu> targets(count);
    // The placement's order: the enabled labels, shuffled.
    std::vector<uint32_t> order;
    for (uint32_t i = 0; i < count; ++i) {
      if (i % 7 != 0) order.push_back(i);
    }
    std::shuffle(order.begin(), order.end(), rng);
    // (with keep-out rectangles where kept apart and anchored: a title and a legend)
    for (const auto& [anchored, apart] : {std::pair{true, true}, {false, true}, {true, false}}) {
      CAPTURE(anchored);
      CAPTURE(apart);
      const std::vector<glm::uvec4> keep_out =
          anchored && apart
              ? std::vector<glm::uvec4>{{0u, 0u, 1024u, 90u}, {800u, 700u, 1000u, 1024u}}
              : std::vector<glm::uvec4>{};
      GpuForces forces(ctx, count);
      std::vector<gpu::LabelStateGpu> state(count);
      for (int frame = 0; frame < 10; ++frame) {
        CAPTURE(frame);
        for (uint32_t i = 0; i < count; ++i) {
          labels[i] = label_at({pixel(rng), pixel(rng)}, i % 7 != 0);
          targets[i] = target_at({pixel(rng), pixel(rng)}, i % 5 != 0);
          if (i % 3 == 0) {  // the placement kept the held position
            labels[i].held = targets[i].position + glm::vec2(0.25f, -0.5f);
            labels[i].hold = 5.0f;
          }
        }
        // Frames of varied length: one sub-step, several, and a still frame.
        const double seconds = frame == 3 ? 0.0 : 0.02 * (frame + 1);
        const ForceSettings settings{
            .anchor_relative = anchored, .speed_widths = widths(900.0f), .keep_apart = apart};
        const auto drawn =
            forces.frame(labels, targets, settings, kUnits, seconds, order, keep_out);
        gpu::ForcesParams params =
            forces_params(settings, kUnits, count, seconds, false, uint32_t(order.size()));
        set_keep_out(params, keep_out);
        const std::vector<gpu::PlacementGpu> expected =
            forces_reference(labels, targets, state, params, order);
        const std::vector<gpu::LabelStateGpu> gpu_state = forces.state();
        // Bit for bit on a CPU device (lavapipe rounds as the C++ does); elsewhere within 1e-3 px:
        // Vulkan lets a GPU divide and take square roots to a few ulps, and fuse multiply-adds.
        const float tolerance =
            ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0.0f : 1e-3f;
        const auto close = [tolerance](glm::vec2 a, glm::vec2 b) {
          return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::vec2(tolerance)));
        };
        int mismatches = 0;
        for (uint32_t i = 0; i < count; ++i) {
          const bool same =
              close(drawn[i].position, expected[i].position) &&
              drawn[i].shown == expected[i].shown &&
              close(gpu_state[i].position, state[i].position) &&
              close(gpu_state[i].drawn, state[i].drawn) &&
              close(gpu_state[i].target, state[i].target) && gpu_state[i].cost == state[i].cost &&
              gpu_state[i].opacity == state[i].opacity && drawn[i].opacity == expected[i].opacity &&
              gpu_state[i].flags == state[i].flags &&
              std::abs(gpu_state[i].blocked - state[i].blocked) <= 1e-6f;
          if (!same && mismatches++ < 3) {
            MESSAGE("label " << i << ": gpu " << drawn[i].position.x << "," << drawn[i].position.y
                             << " opacity " << gpu_state[i].opacity << " waited "
                             << gpu_state[i].blocked << ", cpu " << expected[i].position.x << ","
                             << expected[i].position.y << " opacity " << state[i].opacity
                             << " waited " << state[i].blocked);
          }
        }
        // The state the next frame starts from is the reference's (tolerance does not build up).
        state = gpu_state;
        CHECK(mismatches == 0);
      }
    }
  }

  // The path of the size and frame rate test once on the GPU: the CPU reference's positions.
  TEST_CASE_FIXTURE(test::GpuTest, "forces_pass_follows_a_camera_path_as_the_cpu_reference") {
    GpuForces forces(ctx, kPathLabels);
    const ForceSettings settings = kAlone;
    const ForcesFrame on_gpu = [&](const std::vector<gpu::LabelGpu>& labels,
                                   const std::vector<gpu::PlacementGpu>& targets, LabelUnits units,
                                   double seconds) {
      return forces.frame(labels, targets, settings, units, seconds);
    };
    const auto gpu = offsets_along_path(128.0f, 12, on_gpu);
    const auto cpu = offsets_along_path(128.0f, 12, reference_frames(settings));
    // Bit for bit on a CPU device; elsewhere within 1e-3 px (forces_pass_matches_cpu_reference).
    const float tolerance =
        ctx.properties().deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU ? 0.0f : 1e-3f / 128.0f;
    float largest = 0.0f;
    for (size_t f = 0; f < cpu.size(); ++f) {
      for (int i = 0; i < kPathLabels; ++i) {
        largest = std::max(largest, glm::length(gpu[f][size_t(i)] - cpu[f][size_t(i)]));
      }
    }
    CHECK(largest <= tolerance);
  }

  // Beside the frames, each frame moves the targets of an older placement with their anchors.
  TEST_CASE_FIXTURE(test::GpuTest,
                    "follow_pass_moves_targets_with_their_anchors_as_the_reference") {
    const uint32_t count = 100;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> pixel(0.0f, 512.0f);
    std::vector<gpu::LabelGpu> labels(count), placed(count);
    std::vector<gpu::PlacementGpu> targets(count);
    for (uint32_t i = 0; i < count; ++i) {
      placed[i] = label_at({pixel(rng), pixel(rng)}, i % 6 != 0);  // (some unseen then)
      labels[i] = label_at({pixel(rng), pixel(rng)});
      targets[i] = target_at({pixel(rng), pixel(rng)}, i % 4 != 0);
    }
    const auto buffer = [this](const auto& values) {
      Buffer b(ctx, values.size() * sizeof(values[0]), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
               MemoryKind::device_local);
      upload(ctx, b, as_bytes(values));
      return b;
    };
    const Buffer labels_buffer = buffer(labels), placed_buffer = buffer(placed),
                 targets_buffer = buffer(targets);
    for (const bool anchored : {true, false}) {
      CAPTURE(anchored);
      LabelForces forces(ctx, count);
      graph::Graph g;
      const auto imported = [&g](const char* name, const Buffer& b) {
        return g.import_buffer(name, {.buffer = b.handle(), .has_content = true});
      };
      const graph::ResourceId followed =
          forces.add_follow(g, imported("labels", labels_buffer), imported("placed", placed_buffer),
                            imported("targets", targets_buffer));
      graph::GraphRunner runner(ctx, std::move(g));
      runner.set_viewport({512, 512});
      const ForceSettings settings{.anchor_relative = anchored};
      forces.set_frame(settings, kUnits, 1.0 / 30.0);
      runner.run_now();
      const auto gpu = as<gpu::PlacementGpu>(runner.download_buffer(followed));
      const auto cpu = follow_reference(targets, placed, labels, forces.params());
      int mismatches = 0, moved = 0;
      for (uint32_t i = 0; i < count; ++i) {
        if (gpu[i].position != cpu[i].position || gpu[i].shown != cpu[i].shown) ++mismatches;
        if (cpu[i].position != targets[i].position) ++moved;
        // A label the placement did not see has no target; the others keep theirs.
        CHECK(cpu[i].shown == (i % 6 != 0 && i % 4 != 0 ? PLACEMENT_SHOWN : PLACEMENT_HIDDEN));
        if (anchored) {
          const glm::vec2 offset = cpu[i].position - labels[i].anchor;
          CHECK(glm::length(offset - (targets[i].position - placed[i].anchor)) < 1e-3f);
        }
      }
      CHECK(mismatches == 0);
      CHECK(moved == (anchored ? int(count) : 0));
    }
  }
}

}  // namespace strata
