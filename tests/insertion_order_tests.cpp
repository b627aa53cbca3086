// Insertion orders: scene, Stein and Décoret's (Jump Flooding distance transform and Apollonius
// diagram), and random.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "labeling/insertion_order.h"

namespace strata {
namespace {

struct Image {
  uint32_t width, height;
  std::vector<float> occupancy;
};

// Foreground (1) with background (0) discs at the given centres and radii.
Image with_background_discs(uint32_t width, uint32_t height, std::span<const glm::vec3> discs) {
  Image image{width, height, std::vector<float>(size_t(width) * height, 1.0f)};
  for (uint32_t y = 0; y < height; ++y) {
    for (uint32_t x = 0; x < width; ++x) {
      for (const glm::vec3& disc : discs) {
        if (glm::distance(glm::vec2(x, y), glm::vec2(disc)) <= disc.z) {
          image.occupancy[size_t(y) * width + x] = 0.0f;
        }
      }
    }
  }
  return image;
}

// A foreground disc of `radius` centred in a square background image of side `size`.
Image foreground_disc(uint32_t size, float radius) {
  Image image{size, size, std::vector<float>(size_t(size) * size, 0.0f)};
  const glm::vec2 centre(0.5f * float(size));
  for (uint32_t y = 0; y < size; ++y) {
    for (uint32_t x = 0; x < size; ++x) {
      const bool inside = glm::distance(glm::vec2(x, y) + 0.5f, centre) <= radius;
      image.occupancy[size_t(y) * size + x] = inside ? 1.0f : 0.0f;
    }
  }
  return image;
}

std::vector<float> brute_force_distance_transform(const Image& image) {
  std::vector<float> distance(image.occupancy.size(), std::numeric_limits<float>::infinity());
  for (size_t p = 0; p < distance.size(); ++p) {
    for (size_t q = 0; q < distance.size(); ++q) {
      if (image.occupancy[q] >= 0.5f) continue;
      const glm::vec2 d(float(p % image.width) - float(q % image.width),
                        float(p / image.width) - float(q / image.width));
      distance[p] = std::min(distance[p], glm::length(d));
    }
  }
  return distance;
}

bool is_permutation_of_indices(std::vector<uint32_t> order) {
  std::sort(order.begin(), order.end());
  return order == scene_order(uint32_t(order.size()));
}

}  // namespace

TEST_SUITE("cpu") {
  TEST_CASE("scene_order_counts_up_from_zero") {
    CHECK(scene_order(4) == std::vector<uint32_t>{0, 1, 2, 3});
    CHECK(scene_order(0).empty());
  }

  TEST_CASE("jump_flooding_distance_transform_is_within_a_pixel_of_brute_force") {
    const glm::vec3 discs[] = {{5, 4, 2}, {30, 8, 3}, {12, 22, 4}, {36, 27, 1}, {22, 15, 0}};
    const Image image = with_background_discs(40, 30, discs);
    const std::vector<float> jfa =
        jump_flooding_distance_transform(image.occupancy, image.width, image.height);
    const std::vector<float> exact = brute_force_distance_transform(image);
    // JFA is approximate: a pixel may keep a seed that is not the nearest, never a closer one. The
    // bound asserted is 1 pixel, and nearly every pixel must be exact.
    size_t exact_pixels = 0;
    for (size_t p = 0; p < exact.size(); ++p) {
      CAPTURE(p);
      CHECK(jfa[p] >= exact[p] - 1e-5f);
      CHECK(jfa[p] <= exact[p] + 1.0f);
      exact_pixels += std::abs(jfa[p] - exact[p]) < 1e-5f;
    }
    CHECK(double(exact_pixels) >= 0.99 * double(exact.size()));
  }

  TEST_CASE("jump_flooding_distance_transform_without_background_is_infinite") {
    const std::vector<float> occupancy(12, 1.0f);
    for (const float d : jump_flooding_distance_transform(occupancy, 4, 3)) CHECK(std::isinf(d));
    CHECK_THROWS(jump_flooding_distance_transform(occupancy, 5, 3));
  }

  TEST_CASE("apollonius_order_places_a_disc_centre_first_and_its_edge_last") {
    const Image image = foreground_disc(64, 24.0f);
    const std::vector<glm::vec2> anchors = {{53.5f, 32.5f}, {32.5f, 32.5f}, {32.5f, 20.5f}};
    std::vector<int32_t> diagram;
    const auto order = apollonius_order(anchors, image.occupancy, 64, 64, &diagram);
    CHECK(order == std::vector<uint32_t>{1, 2, 0});  // centre, mid-radius, edge
    REQUIRE(diagram.size() == 64 * 64);
    CHECK(diagram[32 * 64 + 32] == 1);
    CHECK(std::count(diagram.begin(), diagram.end(), -1) == 0);
  }

  TEST_CASE("apollonius_diagram_by_jump_flooding_matches_brute_force_on_most_pixels") {
    const Image image = foreground_disc(64, 28.0f);
    const std::vector<glm::vec2> anchors = {
        {32.5f, 32.5f}, {20.5f, 30.5f}, {44.2f, 40.7f}, {32.5f, 10.5f}, {10.5f, 50.5f}};
    std::vector<int32_t> diagram;
    apollonius_order(anchors, image.occupancy, 64, 64, &diagram);
    const std::vector<float> distance = jump_flooding_distance_transform(image.occupancy, 64, 64);
    size_t agreeing = 0;
    for (uint32_t y = 0; y < 64; ++y) {
      for (uint32_t x = 0; x < 64; ++x) {
        float best = std::numeric_limits<float>::infinity();
        int32_t owner = -1;
        for (size_t k = 0; k < anchors.size(); ++k) {
          const auto a = glm::ivec2(glm::floor(anchors[k]));
          const float weight = distance[size_t(a.y) * 64 + size_t(a.x)];
          const float c = glm::distance(glm::vec2(x, y) + 0.5f, anchors[k]) - weight;
          if (c < best) {
            best = c;
            owner = int32_t(k);
          }
        }
        agreeing += diagram[size_t(y) * 64 + x] == owner;
      }
    }
    CHECK(double(agreeing) >= 0.99 * 64.0 * 64.0);
  }

  TEST_CASE("apollonius_order_puts_anchors_on_background_or_outside_last_by_index") {
    const Image image = foreground_disc(32, 12.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const std::vector<glm::vec2> anchors = {
        {-4.0f, 5.0f}, {1.5f, 1.5f}, {16.0f, 16.0f}, {nan, 3.0f}, {16.0f, 24.0f}};
    std::vector<int32_t> diagram;
    CHECK(apollonius_order(anchors, image.occupancy, 32, 32, &diagram) ==
          std::vector<uint32_t>{2, 4, 0, 1, 3});
    CHECK(std::count(diagram.begin(), diagram.end(), 0) == 0);  // outside: no cell
  }

  TEST_CASE("apollonius_order_without_background_is_the_scene_order_and_plain_voronoi") {
    const std::vector<float> occupancy(16 * 16, 1.0f);
    const std::vector<glm::vec2> anchors = {{12.5f, 12.5f}, {3.5f, 3.5f}};
    std::vector<int32_t> diagram;
    CHECK(apollonius_order(anchors, occupancy, 16, 16, &diagram) == scene_order(2));
    CHECK(diagram[0] == 1);
    CHECK(diagram[15 * 16 + 15] == 0);
  }

  TEST_CASE("random_order_is_a_deterministic_permutation") {
    const auto a = random_order(100, 5);
    CHECK(is_permutation_of_indices(a));
    CHECK(a == random_order(100, 5));
    CHECK(a != random_order(100, 6));
    CHECK(a != scene_order(100));
    CHECK(random_order(0, 1).empty());
    CHECK(random_order(1, 1) == std::vector<uint32_t>{0});
  }
}

}  // namespace strata
