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

// An image 1024 px wide (a pixel is 1/1024 of its width, exact in a float) and 14 px text.
constexpr LabelUnits kUnits{1024.0f, 14.0f};
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

// One label followed over frames of `seconds` toward a fixed target: the distances, frame by frame.
std::vector<float> approach(const ForceSettings& settings, glm::vec2 start, glm::vec2 goal,
                            int frames, double seconds = 1.0 / 30.0) {
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
    const auto drawn = run(labels, targets, {width, 14.0f}, f == 0 ? 0.0 : 1.0 / fps);
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
        forces_(ctx, count) {
    graph::Graph g;
    const graph::ResourceId state = forces_.import_state(g);
    const auto imported = [&g](const char* name, const Buffer& buffer) {
      return g.import_buffer(name, {.buffer = buffer.handle(), .has_content = true});
    };
    drawn_ = forces_
                 .add_to(g, {.labels = imported("labels", labels_),
                             .targets = imported("targets", targets_),
                             .state = state})
                 .drawn;
    runner_ = std::make_unique<graph::GraphRunner>(ctx, std::move(g));
    runner_->set_viewport({512, 512});
  }

  // One frame: where the labels are drawn.
  std::vector<gpu::PlacementGpu> frame(const std::vector<gpu::LabelGpu>& labels,
                                       const std::vector<gpu::PlacementGpu>& targets,
                                       const ForceSettings& settings, LabelUnits units,
                                       double seconds) {
    upload(ctx_, labels_, as_bytes(labels));
    upload(ctx_, targets_, as_bytes(targets));
    forces_.set_frame(settings, units, seconds);
    runner_->run_now();
    return as<gpu::PlacementGpu>(runner_->download_buffer(drawn_));
  }
  std::vector<gpu::LabelStateGpu> state() const { return forces_.state(); }

 private:
  Context& ctx_;
  Buffer labels_, targets_;
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
    CHECK_THROWS_AS(forces_params({}, {0.0f, 14.0f}, 1, 0.1), Error);
  }

  TEST_CASE("speeds_and_distances_are_shares_of_the_width_paddings_of_the_text_size") {
    const ForceSettings s{.appear_padding_em = 0.5f};
    for (const float width : {128.0f, 1920.0f}) {
      const gpu::ForcesParams p = forces_params(s, {width, 20.0f}, 1, 1.0 / 30.0, true);
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
    const ForceSettings settings;
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
    const ForceSettings settings{.anchor_relative = true, .fade_seconds = 0.3f};
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
}

TEST_SUITE("gpu") {
  TEST_CASE_FIXTURE(test::GpuTest, "forces_pass_matches_cpu_reference_over_frames") {
    const uint32_t count = 150;  // more than one workgroup
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> pixel(0.0f, 512.0f);
    std::vector<gpu::LabelGpu> labels(count);
    std::vector<gpu::PlacementGpu> targets(count);
    for (const bool anchored : {true, false}) {
      CAPTURE(anchored);
      GpuForces forces(ctx, count);
      std::vector<gpu::LabelStateGpu> state(count);
      for (int frame = 0; frame < 6; ++frame) {
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
        const ForceSettings settings{.anchor_relative = anchored, .speed_widths = widths(900.0f)};
        const auto drawn = forces.frame(labels, targets, settings, kUnits, seconds);
        const std::vector<gpu::PlacementGpu> expected = forces_reference(
            labels, targets, state, forces_params(settings, kUnits, count, seconds));
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
              gpu_state[i].flags == state[i].flags;
          if (!same && mismatches++ < 3) {
            MESSAGE("label " << i << ": gpu " << drawn[i].position.x << "," << drawn[i].position.y
                             << " cpu " << expected[i].position.x << "," << expected[i].position.y);
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
    const ForceSettings settings;
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
}

}  // namespace strata
