// Layering of labels by anchor depth: 1D k-means++ and the layer planes and splits built on it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "labeling/layering.h"

namespace strata {
namespace {

// Values scattered around 1, 5 and 9, interleaved so that no cluster is contiguous in the input.
std::vector<float> three_groups() {
  std::vector<float> values;
  for (int i = 0; i < 10; ++i) {
    const float jitter = 0.05f * float(i % 5) - 0.1f;
    values.push_back(9.0f + jitter);
    values.push_back(1.0f - jitter);
    values.push_back(5.0f + 0.5f * jitter);
  }
  return values;
}

uint32_t splits_below(const std::vector<float>& splits, float depth) {
  return uint32_t(std::count_if(splits.begin(), splits.end(), [&](float s) { return s < depth; }));
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("kmeans_plus_plus_is_deterministic_for_a_seed") {
    std::vector<float> values;
    SplitMix64 rng{99};
    for (int i = 0; i < 200; ++i) values.push_back(float(rng.next_unit() * 10.0));
    std::vector<float> centres_a, centres_b;
    const auto a = kmeans_plus_plus(values, 5, 7, &centres_a);
    const auto b = kmeans_plus_plus(values, 5, 7, &centres_b);
    CHECK(a == b);
    CHECK(centres_a == centres_b);
    CHECK(centres_a.size() == 5);
  }

  TEST_CASE("kmeans_plus_plus_separates_well_separated_clusters_for_every_seed") {
    const std::vector<float> values = three_groups();
    for (uint64_t seed = 0; seed < 32; ++seed) {
      CAPTURE(seed);
      std::vector<float> centres;
      const auto cluster = kmeans_plus_plus(values, 3, seed, &centres);
      REQUIRE(cluster.size() == values.size());
      for (size_t i = 0; i < values.size(); ++i) {
        CHECK(cluster[i] == uint32_t(std::lround((values[i] - 1.0f) / 4.0f)));
      }
      REQUIRE(centres.size() == 3);
      CHECK(centres[0] == doctest::Approx(1.0f).epsilon(0.05));
      CHECK(centres[1] == doctest::Approx(5.0f).epsilon(0.05));
      CHECK(centres[2] == doctest::Approx(9.0f).epsilon(0.05));
    }
  }

  TEST_CASE("kmeans_plus_plus_numbers_clusters_front_to_back") {
    const std::vector<float> values = {9.0f, 8.9f, 5.0f, 5.1f, 1.0f, 0.9f};
    std::vector<float> centres;
    const auto cluster = kmeans_plus_plus(values, 3, 3, &centres);
    CHECK(cluster == std::vector<uint32_t>{2, 2, 1, 1, 0, 0});
    CHECK(std::is_sorted(centres.begin(), centres.end()));
    for (size_t i = 0; i < values.size(); ++i) {
      for (const float c : centres) {
        CHECK(std::abs(values[i] - centres[cluster[i]]) <= std::abs(values[i] - c));
      }
    }
  }

  TEST_CASE("kmeans_plus_plus_clamps_k_to_the_distinct_values") {
    const std::vector<float> values = {7.0f, 3.0f, 7.0f, 3.0f, 7.0f};
    std::vector<float> centres;
    CHECK(kmeans_plus_plus(values, 5, 1, &centres) == std::vector<uint32_t>{1, 0, 1, 0, 1});
    CHECK(centres == std::vector<float>{3.0f, 7.0f});
    CHECK(kmeans_plus_plus(values, 0, 1, &centres) == std::vector<uint32_t>(5, 0));
    CHECK(centres.size() == 1);
  }

  TEST_CASE("kmeans_plus_plus_of_no_values_is_empty") {
    std::vector<float> centres = {1.0f};
    CHECK(kmeans_plus_plus({}, 3, 1, &centres).empty());
    CHECK(centres.empty());
  }

  TEST_CASE("ndc_z_mapping_round_trips_and_maps_near_and_far_to_0_and_1") {
    const float near_plane = 0.1f, far_plane = 100.0f;
    CHECK(eye_depth_to_ndc_z(near_plane, near_plane, far_plane) == 0.0f);
    CHECK(eye_depth_to_ndc_z(far_plane, near_plane, far_plane) == 1.0f);
    float previous = 0.0f;
    for (const float depth : {0.2f, 0.5f, 1.0f, 3.0f, 10.0f, 42.0f, 99.0f}) {
      const float z = eye_depth_to_ndc_z(depth, near_plane, far_plane);
      CHECK(z > previous);
      previous = z;
      // Float z near 1 holds depth to about 1e-4 relative at the far end.
      CHECK(ndc_z_to_eye_depth(z, near_plane, far_plane) == doctest::Approx(depth).epsilon(1e-4));
    }
  }

  TEST_CASE("layer_labels_splits_increase_and_label_layers_follow_them") {
    std::vector<float> depths;
    for (int i = 0; i < 40; ++i) depths.push_back(float(1 << (i % 4)) * (1.0f + 0.01f * float(i)));
    const Layering layering = layer_labels(depths, 4, 0.1f, 100.0f);
    REQUIRE(layering.layer_count == 4);
    REQUIRE(layering.split_depths.size() == 3);
    REQUIRE(layering.plane_depths.size() == 4);
    CHECK(std::adjacent_find(layering.plane_depths.begin(), layering.plane_depths.end(),
                             std::greater_equal<float>()) == layering.plane_depths.end());
    CHECK(std::equal(layering.split_depths.begin(), layering.split_depths.end(),
                     layering.plane_depths.begin()));
    for (size_t i = 0; i < depths.size(); ++i) {
      const uint32_t layer = layering.label_layer[i];
      CHECK(layer == splits_below(layering.split_depths, depths[i]));
      CHECK(layer < layering.layer_count);
    }
  }

  TEST_CASE("layer_labels_puts_a_label_on_a_plane_in_that_layer") {
    // NDC z (near 0.1, far 1000) is about 1 - 0.1 / depth: groups near 0.5, 0.75 and 0.95.
    const std::vector<float> depths = {0.19f, 0.21f, 0.2f, 0.42f, 0.38f, 0.41f, 0.4f, 1.9f, 2.1f};
    const Layering layering = layer_labels(depths, 3, 0.1f, 1000.0f);
    REQUIRE(layering.layer_count == 3);
    for (uint32_t l = 0; l < layering.layer_count; ++l) {
      const auto on_plane = std::find(depths.begin(), depths.end(), layering.plane_depths[l]);
      REQUIRE(on_plane != depths.end());  // the plane is a median anchor's own depth
      CHECK(layering.label_layer[size_t(on_plane - depths.begin())] == l);
    }
    // Lower medians: {0.19, 0.2, 0.21} -> 0.2, {0.38, 0.4, 0.41, 0.42} -> 0.4, {1.9, 2.1} -> 1.9.
    CHECK(layering.plane_depths == std::vector<float>{0.2f, 0.4f, 1.9f});
    CHECK(layering.label_layer == std::vector<uint32_t>{0, 1, 0, 2, 1, 2, 1, 2, 2});
  }

  TEST_CASE("layer_labels_with_one_layer_has_no_splits") {
    const std::vector<float> depths = {2.0f, 8.0f, 3.0f};
    const Layering layering = layer_labels(depths, 1, 0.1f, 10.0f);
    CHECK(layering.layer_count == 1);
    CHECK(layering.split_depths.empty());
    CHECK(layering.plane_depths == std::vector<float>{3.0f});
    CHECK(layering.label_layer == std::vector<uint32_t>(3, 0));
  }

  TEST_CASE("layer_labels_shrinks_the_layer_count_to_the_distinct_depths") {
    const Layering layering = layer_labels(std::vector<float>{2.0f, 5.0f, 2.0f}, 4, 0.1f, 10.0f);
    CHECK(layering.layer_count == 2);
    CHECK(layering.split_depths == std::vector<float>{2.0f});
    CHECK(layering.label_layer == std::vector<uint32_t>{0, 1, 0});
    CHECK(layer_labels(std::vector<float>{}, 4, 0.1f, 10.0f).layer_count == 1);
  }

  TEST_CASE("layer_labels_clusters_in_ndc_z_not_in_eye_depth") {
    // In eye depth 2-means groups {2, 3, 100} | {900}; in NDC z (near 1, far 1000: 0.50, 0.67,
    // 0.99, 0.9999) it groups {2, 3} | {100, 900}: more resolution near the camera.
    const Layering layering =
        layer_labels(std::vector<float>{900.0f, 3.0f, 100.0f, 2.0f}, 2, 1.0f, 1000.0f);
    CHECK(layering.plane_depths == std::vector<float>{2.0f, 100.0f});
    CHECK(layering.label_layer == std::vector<uint32_t>{1, 1, 1, 0});
  }

  TEST_CASE("layer_labels_gives_unusable_anchors_layer_0_and_leaves_them_out") {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<float> usable = {1.0f, 1.2f, 8.0f, 8.5f};
    const std::vector<float> mixed = {nan, 1.0f, 0.1f, 1.2f, -3.0f, 8.0f, 10.0f, 8.5f, 50.0f};
    const Layering reference = layer_labels(usable, 2, 0.1f, 10.0f);
    const Layering layering = layer_labels(mixed, 2, 0.1f, 10.0f);
    CHECK(layering.split_depths == reference.split_depths);
    CHECK(layering.label_layer == std::vector<uint32_t>{0, 0, 0, 1, 0, 1, 0, 1, 0});
  }

  TEST_CASE("layer_hysteresis_keeps_layers_under_a_small_move_and_switches_under_a_large_one") {
    const std::vector<float> before{100, 101, 102, 103, 104, 200, 201, 202};
    const Layering previous = layer_labels(before, 2, 1.0f, 1000.0f);
    REQUIRE(previous.label_layer == std::vector<uint32_t>{0, 0, 0, 1, 1, 1, 1, 1});
    // Unchanged depths: the warm start finds the same planes.
    const Layering same = follow_layering(previous, before, 2, 1.0f, 1000.0f, {});
    CHECK(same.plane_depths == previous.plane_depths);
    CHECK(same.label_layer == previous.label_layer);

    // Half a millimetre moves the front cluster's median: from scratch, labels 2 and 3 swap
    // layers; followed, nobody changes layer.
    std::vector<float> small = before;
    small[3] = 101.5f;
    const Layering fresh = layer_labels(small, 2, 1.0f, 1000.0f);
    CHECK(fresh.label_layer[2] == 1);
    CHECK(fresh.label_layer[3] == 0);
    CHECK(follow_layering(previous, small, 2, 1.0f, 1000.0f, {}).label_layer ==
          previous.label_layer);

    // Far in front of its layer's slab, label 3 does switch; label 2 just behind the moved plane
    // does not.
    std::vector<float> large = before;
    large[3] = 50.0f;
    const Layering moved = follow_layering(previous, large, 2, 1.0f, 1000.0f, {});
    CHECK(moved.label_layer[3] == 0);
    CHECK(moved.label_layer[2] == 0);
    // Without a margin, following is the plain assignment.
    const Layering no_margin = follow_layering(previous, small, 2, 1.0f, 1000.0f, {.margin = 0.0f});
    CHECK(no_margin.label_layer[2] == 1);
  }

  TEST_CASE("a_cluster_that_a_move_empties_keeps_its_layer_and_nobody_is_reclustered") {
    // Three clusters; then the middle one's two anchors move next to the back cluster, so Lloyd's
    // iterations from the previous planes empty it. The layer count stays three (the empty
    // cluster's plane at its centre), and the labels of the other clusters keep their layers.
    const std::vector<float> before{100, 101, 102, 300, 301, 600, 601, 602};
    const Layering previous = layer_labels(before, 3, 1.0f, 1000.0f);
    REQUIRE(previous.layer_count == 3);
    std::vector<float> after = before;
    after[3] = 590.0f;
    after[4] = 592.0f;
    const Layering followed = follow_layering(previous, after, 3, 1.0f, 1000.0f, {});
    CHECK(followed.layer_count == 3);
    CHECK(std::is_sorted(followed.plane_depths.begin(), followed.plane_depths.end()));
    for (const size_t i : {0, 1, 2, 5, 6, 7})
      CHECK(followed.label_layer[i] == previous.label_layer[i]);
  }
}

}  // namespace strata
