// Forces (eq. 3.6-3.8): the GPU pass against its CPU reference, and how a label moves.
#include <doctest/doctest.h>

#include <cstring>
#include <random>

#include "engine/core/error.h"
#include "engine/gpu/resources.h"
#include "engine/graph/graph_runner.h"
#include "gpu_fixture.h"
#include "passes/label_forces.h"

namespace strata {
namespace {

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

// One label followed over frames of 1/30 s toward a fixed target: the distances, frame by frame.
std::vector<float> approach(const ForceSettings& settings, glm::vec2 start, glm::vec2 goal,
                            int frames) {
  const gpu::ForcesParams params = forces_params(settings, 1, 1.0 / 30.0);
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

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("a_frame_is_split_into_steps_that_never_move_a_label_past_epsilon") {
    const ForceSettings s{.speed = 600.0f, .epsilon = 24.0f};
    CHECK(forces_params(s, 1, 1.0 / 30.0).steps == 1);
    const gpu::ForcesParams second = forces_params(s, 1, 1.0);
    CHECK(second.steps == 25);
    CHECK(second.step_seconds * second.speed <= second.epsilon);
    CHECK_THROWS_AS(forces_params({.speed = 0.0f}, 1, 0.1), Error);
  }

  TEST_CASE("a_label_converges_to_a_still_target_without_overshoot_and_stays") {
    const glm::vec2 start{100.0f, 100.0f}, goal{400.0f, 500.0f};  // 500 px apart
    const std::vector<float> d = approach({.speed = 600.0f, .epsilon = 24.0f}, start, goal, 60);
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
    const std::vector<float> d =
        approach({.speed = 600.0f, .epsilon = 24.0f}, {0.0f, 0.0f}, {12.0f, 0.0f}, 1);
    CHECK(d[0] == doctest::Approx(2.0f).epsilon(1e-5));
  }

  TEST_CASE("anchored_labels_move_rigidly_with_their_anchor_screen_labels_lag") {
    std::vector<gpu::LabelStateGpu> anchored(1), screen(1);
    const gpu::ForcesParams a = forces_params({.anchor_relative = true}, 1, 1.0 / 30.0);
    const gpu::ForcesParams s = forces_params({.anchor_relative = false}, 1, 1.0 / 30.0);
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
    const gpu::ForcesParams p = forces_params({.anchor_relative = false}, 2, 1.0 / 30.0);
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
    const gpu::ForcesParams p = forces_params(settings, 1, 1.0 / 30.0);
    CHECK(p.fade == doctest::Approx(1.0f / 9.0f));
    CHECK(forces_params(settings, 1, 0.0).fade == 1.0f);  // a still: at once
    std::vector<gpu::LabelStateGpu> state(1);
    const glm::vec2 offset{50.0f, -20.0f};
    // Shown in a still: fully drawn at once.
    glm::vec2 anchor{100.0f, 100.0f};
    auto drawn = forces_reference({label_at(anchor)}, {target_at(anchor + offset)}, state,
                                  forces_params(settings, 1, 0.0));
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
    const gpu::ForcesParams p = forces_params({.anchor_relative = true}, 1, 1.0 / 30.0);
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
    Buffer label_buffer(ctx, count * sizeof(gpu::LabelGpu), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                        MemoryKind::device_local);
    Buffer target_buffer(ctx, count * sizeof(gpu::PlacementGpu), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                         MemoryKind::device_local);
    for (const bool anchored : {true, false}) {
      CAPTURE(anchored);
      LabelForces forces(ctx, count);
      graph::Graph g;
      const graph::ResourceId state_id = forces.import_state(g);
      const LabelForces::Outputs out = forces.add_to(
          g, {.labels =
                  g.import_buffer("labels", {.buffer = label_buffer.handle(), .has_content = true}),
              .targets = g.import_buffer("targets",
                                         {.buffer = target_buffer.handle(), .has_content = true}),
              .state = state_id});
      graph::GraphRunner runner(ctx, std::move(g));
      runner.set_viewport({512, 512});
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
        upload(ctx, label_buffer, as_bytes(labels));
        upload(ctx, target_buffer, as_bytes(targets));
        // Frames of varied length: one sub-step, several, and a still frame.
        const double seconds = frame == 3 ? 0.0 : 0.02 * (frame + 1);
        const ForceSettings settings{.anchor_relative = anchored, .speed = 900.0f};
        forces.set_frame(settings, seconds);
        runner.run_now();
        const std::vector<gpu::PlacementGpu> expected =
            forces_reference(labels, targets, state, forces_params(settings, count, seconds));
        const auto drawn = as<gpu::PlacementGpu>(runner.download_buffer(out.drawn));
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
}

}  // namespace strata
