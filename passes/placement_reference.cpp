#include "passes/placement_reference.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "passes/summed_area_table.h"
#include "shared/saliency.h"

namespace strata {
namespace gpu {
namespace {

// The shared cost code sees these members as the shader sees its buffers.
struct Placer {
  PlacementParams params;
  std::span<const LabelGpu> labels;
  std::span<const uint32_t> order;
  const std::vector<float>& tables;
  std::vector<uint64_t> results;
  std::vector<PairRegionsGpu> regions;  // the label being placed against each placed label

  std::vector<vec2> anchors;  // every shown label's anchor

  // Every label placed so far, every anchor: the GPU's tile culling only skips what cannot matter.
  uint placed_count() const { return params.step; }
  PairRegionsGpu placed_regions(uint k) const { return regions[order[k]]; }
  uint anchor_count() const { return uint(anchors.size()); }
  vec2 anchor_at(uint k) const { return anchors[k]; }
  vec3 placed(uint j) const {
    if (results[j] == PLACEMENT_NONE) return vec3(0.0f);
    const uint pixel = uint(results[j] & 0xFFFFFFFFu);
    const uvec2 p(pixel % params.width, pixel / params.width);
    return vec3(box_origin(p, labels[j].size) + labels[j].size * 0.5f, 1.0f);
  }
  float table_at(uint layer, int x, int y) const {
    if (x < 0 || y < 0) return 0.0f;
    return tables[size_t(layer) * params.width * params.height + size_t(y) * params.width +
                  size_t(x)];
  }

#include "shared/placement_cost.h"
};

}  // namespace
}  // namespace gpu

ReferencePlacement place_reference(std::span<const uint8_t> final_rgba8,
                                   std::span<const glm::vec4> layers, uint32_t layer_count,
                                   std::span<const gpu::LabelGpu> labels,
                                   std::span<const uint32_t> order,
                                   const PlacementSettings& settings, graph::Extent size) {
  const uint32_t w = size.width, h = size.height;
  const size_t pixels = size_t{w} * h;
  ReferencePlacement out;
  // Saliency: CIELAB of each pixel, Sobel with clamp-to-edge neighbours.
  std::vector<glm::vec3> lab(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    lab[p] = gpu::rgb_to_lab(
        glm::vec3(final_rgba8[4 * p], final_rgba8[4 * p + 1], final_rgba8[4 * p + 2]) / 255.0f);
  }
  const auto at = [&](int x, int y) {
    return lab[size_t(std::clamp(y, 0, int(h) - 1)) * w + size_t(std::clamp(x, 0, int(w) - 1))];
  };
  out.saliency.resize(pixels);
  for (int y = 0; y < int(h); ++y) {
    for (int x = 0; x < int(w); ++x) {
      out.saliency[size_t(y) * w + size_t(x)] =
          gpu::sobel_saliency(at(x - 1, y - 1), at(x, y - 1), at(x + 1, y - 1), at(x - 1, y),
                              at(x + 1, y), at(x - 1, y + 1), at(x, y + 1), at(x + 1, y + 1));
    }
  }
  // Integral costs per layer and their tables.
  out.costs.resize(pixels * layer_count);
  out.tables.resize(out.costs.size());
  for (size_t p = 0; p < pixels; ++p) {
    float all = 0.0f;
    for (uint32_t l = 0; l < layer_count; ++l) all += layers[l * pixels + p].a;
    float in_front = 0.0f;
    for (uint32_t l = 0; l < layer_count; ++l) {
      in_front += layers[l * pixels + p].a;
      out.costs[l * pixels + p] = gpu::integral_cost(
          in_front, all - in_front, all, out.saliency[p], layer_count, settings.saliency_weight,
          settings.occlusion_weight, settings.single_saliency_weight);
    }
  }
  for (uint32_t l = 0; l < layer_count; ++l) {
    const std::vector<double> table =
        summed_area_table_reference(std::span(out.costs).subspan(l * pixels, pixels), w, h);
    for (size_t p = 0; p < pixels; ++p) out.tables[l * pixels + p] = float(table[p]);
  }
  // The greedy loop: each label's argmin over every pixel (ties: the lowest pixel index).
  gpu::Placer placer{placement_params(settings, size, layer_count, uint32_t(labels.size()), 0),
                     labels,
                     order,
                     out.tables,
                     std::vector<uint64_t>(labels.size(), PLACEMENT_NONE),
                     std::vector<gpu::PairRegionsGpu>(labels.size()),
                     {}};
  for (const gpu::LabelGpu& l : labels) {
    if ((l.flags & LABEL_ENABLED) != 0u) placer.anchors.push_back(l.anchor);
  }
  out.constraints.assign(pixels, 0u);
  for (uint32_t step = 0; step < order.size(); ++step) {
    placer.params.step = step;
    const uint32_t label = order[step];
    const gpu::LabelGpu& me = labels[label];
    for (uint32_t k = 0; k < step; ++k) {
      const uint32_t j = order[k];
      placer.regions[j] = placer.pair_regions(me, labels[j], placer.placed(j), settings.margin);
    }
    for (uint32_t y = 0; y < h; ++y) {
      for (uint32_t x = 0; x < w; ++x) {
        const glm::uvec2 p(x, y);
        if (!placer.candidate_allowed(me, p)) continue;
        const glm::vec2 origin = gpu::box_origin(p, me.size);
        const glm::vec2 centre = origin + me.size * 0.5f;
        const uint32_t bits =
            placer.constraint_bits(me, centre, 0u, std::numeric_limits<float>::infinity());
        const uint32_t pixel = y * w + x;
        if (settings.write_constraints) out.constraints[pixel] = bits;
        if (settings.hard && bits != 0u) continue;
        const float cost = placer.candidate_cost(me, origin, centre, bits);
        uint32_t cost_bits;
        std::memcpy(&cost_bits, &cost, 4);
        placer.results[label] =
            std::min(placer.results[label], (uint64_t(cost_bits) << 32) | pixel);
      }
    }
  }
  out.placements.resize(labels.size());
  for (size_t i = 0; i < labels.size(); ++i) {
    const uint64_t r = placer.results[i];
    gpu::PlacementGpu& result = out.placements[i];
    if (r == PLACEMENT_NONE || (labels[i].flags & LABEL_ENABLED) == 0u) {
      result = gpu::hidden_placement(labels[i]);
      continue;
    }
    const uint32_t cost_bits = uint32_t(r >> 32);
    float cost;
    std::memcpy(&cost, &cost_bits, 4);
    result = gpu::shown_placement(labels[i], uint32_t(r & 0xFFFFFFFFu), cost, w);
  }
  return out;
}

}  // namespace strata
