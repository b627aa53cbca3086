#include "labeling/insertion_order.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

#include "labeling/layering.h"

namespace strata {

namespace {

constexpr int32_t no_seed = -1;
constexpr double infinity = std::numeric_limits<double>::infinity();

glm::dvec2 pixel_centre(uint32_t x, uint32_t y) {
  return {x + 0.5, y + 0.5};
}

// Jump Flooding (Rong and Tan 2006): `nearest` holds a seed id per pixel (or no_seed); each pass
// with step s lets every pixel adopt the seed of any of its 8 neighbours at distance s when
// `cost(pixel, seed)` is lower. Steps halve from half the larger side (rounded up to a power of
// two) down to 1, so every seed's flood can reach every pixel in log2(size) passes.
template <class Cost>
std::vector<int32_t> jump_flood(std::vector<int32_t> nearest, uint32_t width, uint32_t height,
                                Cost cost) {
  std::vector<int32_t> next(nearest.size());
  for (uint32_t step = std::bit_ceil(std::max(width, height)) / 2; step >= 1; step /= 2) {
    const int64_t s = step;
    for (uint32_t y = 0; y < height; ++y) {
      for (uint32_t x = 0; x < width; ++x) {
        int32_t best = nearest[size_t(y) * width + x];
        double best_cost = best == no_seed ? infinity : cost(x, y, best);
        for (int64_t dy = -s; dy <= s; dy += s) {
          for (int64_t dx = -s; dx <= s; dx += s) {
            const int64_t qx = x + dx, qy = y + dy;
            if (qx < 0 || qy < 0 || qx >= width || qy >= height) continue;
            const int32_t seed = nearest[size_t(qy) * width + size_t(qx)];
            if (seed == no_seed || seed == best) continue;
            const double c = cost(x, y, seed);
            if (c < best_cost) {
              best = seed;
              best_cost = c;
            }
          }
        }
        next[size_t(y) * width + x] = best;
      }
    }
    nearest.swap(next);
  }
  return nearest;
}

bool is_background(float occupancy) {
  return occupancy < 0.5f;
}

// The pixel an anchor lies in, or no_seed outside the image (and for NaN coordinates).
int32_t anchor_pixel(glm::vec2 anchor, uint32_t width, uint32_t height) {
  const float x = std::floor(anchor.x), y = std::floor(anchor.y);
  if (!(x >= 0.0f && y >= 0.0f && x < float(width) && y < float(height))) return no_seed;
  return int32_t(uint32_t(y) * width + uint32_t(x));
}

std::vector<float> anchor_weights(std::span<const glm::vec2> anchors_px,
                                  const std::vector<float>& distance, uint32_t width,
                                  uint32_t height) {
  std::vector<float> weight(anchors_px.size(), 0.0f);
  for (size_t k = 0; k < anchors_px.size(); ++k) {
    const int32_t pixel = anchor_pixel(anchors_px[k], width, height);
    // Infinite: no background anywhere, every anchor equally inside, so all weights are 0.
    if (pixel != no_seed && std::isfinite(distance[size_t(pixel)])) {
      weight[k] = distance[size_t(pixel)];
    }
  }
  return weight;
}

std::vector<int32_t> apollonius_diagram(std::span<const glm::vec2> anchors_px,
                                        const std::vector<float>& weight, uint32_t width,
                                        uint32_t height) {
  const auto cost = [&](uint32_t x, uint32_t y, int32_t k) {
    const glm::dvec2 anchor(anchors_px[size_t(k)]);
    return glm::length(pixel_centre(x, y) - anchor) - double(weight[size_t(k)]);
  };
  // Each anchor seeds its own pixel; of several anchors in one pixel the cheapest there wins.
  std::vector<int32_t> nearest(size_t(width) * height, no_seed);
  for (size_t k = 0; k < anchors_px.size(); ++k) {
    const int32_t pixel = anchor_pixel(anchors_px[k], width, height);
    if (pixel == no_seed) continue;
    int32_t& owner = nearest[size_t(pixel)];
    const uint32_t x = uint32_t(pixel) % width, y = uint32_t(pixel) / width;
    if (owner == no_seed || cost(x, y, int32_t(k)) < cost(x, y, owner)) owner = int32_t(k);
  }
  return jump_flood(std::move(nearest), width, height, cost);
}

}  // namespace

std::vector<uint32_t> scene_order(uint32_t count) {
  std::vector<uint32_t> order(count);
  std::iota(order.begin(), order.end(), 0u);
  return order;
}

std::vector<float> jump_flooding_distance_transform(std::span<const float> occupancy,
                                                    uint32_t width, uint32_t height) {
  if (occupancy.size() != size_t(width) * height) {
    throw std::invalid_argument("jump_flooding_distance_transform: occupancy holds " +
                                std::to_string(occupancy.size()) + " values, expected " +
                                std::to_string(size_t(width) * height));
  }
  std::vector<int32_t> nearest(size_t(width) * height, no_seed);
  for (size_t i = 0; i < nearest.size(); ++i) {
    if (is_background(occupancy[i])) nearest[i] = int32_t(i);
  }
  const auto squared_distance = [width](uint32_t x, uint32_t y, int32_t seed) {
    const double dx = double(x) - double(uint32_t(seed) % width);
    const double dy = double(y) - double(uint32_t(seed) / width);
    return dx * dx + dy * dy;
  };
  nearest = jump_flood(std::move(nearest), width, height, squared_distance);
  std::vector<float> distance(nearest.size(), std::numeric_limits<float>::infinity());
  for (size_t i = 0; i < nearest.size(); ++i) {
    if (nearest[i] == no_seed) continue;
    const uint32_t x = uint32_t(i % width), y = uint32_t(i / width);
    distance[i] = float(std::sqrt(squared_distance(x, y, nearest[i])));
  }
  return distance;
}

std::vector<uint32_t> apollonius_order(std::span<const glm::vec2> anchors_px,
                                       std::span<const float> occupancy, uint32_t width,
                                       uint32_t height, std::vector<int32_t>* diagram) {
  const std::vector<float> distance = jump_flooding_distance_transform(occupancy, width, height);
  const std::vector<float> weight = anchor_weights(anchors_px, distance, width, height);
  if (diagram) *diagram = apollonius_diagram(anchors_px, weight, width, height);
  std::vector<uint32_t> order = scene_order(uint32_t(anchors_px.size()));
  // Stable: equal weights keep ascending anchor index.
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return weight[a] > weight[b]; });
  return order;
}

std::vector<uint32_t> random_order(uint32_t count, uint64_t seed) {
  std::vector<uint32_t> order = scene_order(count);
  SplitMix64 rng{seed};
  for (uint32_t i = count; i > 1; --i) {
    const auto j = static_cast<uint32_t>(rng.next_below(i));
    std::swap(order[i - 1], order[j]);
  }
  return order;
}

}  // namespace strata
